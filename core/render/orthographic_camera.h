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
        rays.org = Vec3<N>(corner_) + Vec3<N>(du_) * px + Vec3<N>(dv_) * py;
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
