// Pinhole camera: all rays of a packet share the eye point (common origin).
#pragma once
#include <cmath>

#include "core/concepts/camera.h"
#include "core/math/aabb.h"

namespace rtfact {

struct CameraFrame {
    Vec3f eye{0, 0, 1}, at{0, 0, 0}, up{0, 1, 0};
    float fovDeg = 45.0f;  // vertical field of view (orthographic: unused)
};

class PinholeCamera {
   public:
    PinholeCamera() = default;
    PinholeCamera(const CameraFrame& f, int w, int h) : frame_(f), w_(w), h_(h) {
        const Vec3f fwd = normalize(f.at - f.eye);
        const Vec3f right = normalize(cross(fwd, f.up));
        const Vec3f upv = cross(right, fwd);
        const float tanHalf = std::tan(0.5f * f.fovDeg * 3.14159265f / 180.0f);
        const float pix = 2.0f * tanHalf / float(h);  // image-plane size of one pixel at distance 1
        du_ = right * pix;
        dv_ = upv * (-pix);
        corner_ = fwd - du_ * (0.5f * float(w)) - dv_ * (0.5f * float(h));
        pixelAngle_ = pix;
    }

    // (px, py): continuous pixel coordinates, (0, 0) the top-left corner of the image.
    // Chunk by chunk, so that every packet size runs the same native-width expression and
    // the compiler contracts it into the same FMAs: a pixel's ray is bit-identical for
    // any N. (Whole-packet arithmetic on 32 AVX2 chunks was left uncontracted, and rays
    // differed from the 64-ray packets' in the last bit.)
    template <int N>
    RTFACT_INLINE void generate(const Packet<N>& px, const Packet<N>& py, RayPacket<N>& rays) const {
        constexpr int W = Packet<N>::W;
        for (int k = 0; k < Packet<N>::C; ++k) {
            const Vec3<W> d = Vec3<W>(corner_) + Vec3<W>(du_) * px.chunk(k) + Vec3<W>(dv_) * py.chunk(k);
            rays.dir.setChunk(k, normalize(d));
        }
        rays.org = Vec3<N>(frame_.eye);
        rays.tMin = Packet<N>(0.0f);
        rays.tMax = Packet<N>(kInfinity);
        rays.commonOrigin = true;
        rays.finalize();
    }
    RayCone cone() const { return {0.0f, pixelAngle_}; }
    int width() const { return w_; }
    int height() const { return h_; }
    const CameraFrame& frame() const { return frame_; }

   private:
    CameraFrame frame_;
    int w_ = 1, h_ = 1;
    Vec3f corner_, du_, dv_;
    float pixelAngle_ = 0;
};
static_assert(Camera<PinholeCamera>);

// A frame looking at the whole of `box` from direction `viewDir` (from target to eye).
inline CameraFrame fitCamera(const AABB& box, float fovDeg, float aspect, Vec3f viewDir = {0.6f, 0.45f, 1.0f},
                             Vec3f up = {0, 1, 0}) {
    CameraFrame f;
    f.fovDeg = fovDeg;
    f.up = up;
    if (box.isEmpty()) return f;
    const Vec3f c = box.center();
    const float radius = std::max(0.5f * length(box.extent()), 1e-6f);
    const float halfV = 0.5f * fovDeg * 3.14159265f / 180.0f;
    const float halfMin = aspect < 1.0f ? std::atan(std::tan(halfV) * aspect) : halfV;
    const float dist = radius / std::sin(halfMin);
    f.at = c;
    f.eye = c + normalize(viewDir) * dist;
    if (std::fabs(dot(normalize(viewDir), normalize(up))) > 0.999f) f.up = Vec3f(0, 0, 1);
    return f;
}

}  // namespace rtfact
