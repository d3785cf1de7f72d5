// Orthographic camera: parallel rays; the view height in world units is given.
#pragma once
#include "core/concepts/camera.h"
#include "core/render/pinhole_camera.h"

namespace rtfact {

class OrthographicCamera {
   public:
    OrthographicCamera() = default;
    OrthographicCamera(const CameraFrame& f, float viewHeight, int w, int h) : w_(w), h_(h) {
        fwd_ = normalize(f.at - f.eye);
        const Vec3f right = normalize(cross(fwd_, f.up));
        const Vec3f upv = cross(right, fwd_);
        const float pix = viewHeight / float(h);
        du_ = right * pix;
        dv_ = upv * (-pix);
        corner_ = f.eye - du_ * (0.5f * float(w)) - dv_ * (0.5f * float(h));
        pixel_ = pix;
    }
    template <int N>
    RTFACT_INLINE void generate(const Packet<N>& px, const Packet<N>& py, RayPacket<N>& rays) const {
        // chunk by chunk: bit-identical origins at every packet size (see PinholeCamera)
        constexpr int W = Packet<N>::W;
        for (int k = 0; k < Packet<N>::C; ++k)
            rays.org.setChunk(k, Vec3<W>(corner_) + Vec3<W>(du_) * px.chunk(k) + Vec3<W>(dv_) * py.chunk(k));
        rays.dir = Vec3<N>(fwd_);
        rays.tMin = Packet<N>(0.0f);
        rays.tMax = Packet<N>(kInfinity);
        rays.commonOrigin = false;
        rays.finalize();
    }
    RayCone cone() const { return {pixel_, 0.0f}; }
    int width() const { return w_; }
    int height() const { return h_; }

   private:
    int w_ = 1, h_ = 1;
    Vec3f corner_, du_, dv_, fwd_;
    float pixel_ = 0;
};
static_assert(Camera<OrthographicCamera>);

}  // namespace rtfact
