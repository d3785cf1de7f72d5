// Textures for surfaces (models of the core's Texture concept): constant, procedural
// checker, and images (loaded through the core's OpenImageIO reader) with bilinear
// filtering and repeat wrapping.
#pragma once
#include <cmath>
#include <memory>

#include "core/concepts/texture.h"
#include "core/render/image_io.h"

namespace rtfact::surfaces {

struct ConstantTexture {
    Vec3f value{1.0f};
    template <int N>
    Vec3<N> lookup(const Packet<N>&, const Packet<N>&, const Vec3<N>&) const {
        return Vec3<N>(value);
    }
};
static_assert(Texture<ConstantTexture>);

// Checker in uv space: `scale` squares per unit.
struct CheckerTexture {
    Vec3f a{0.9f}, b{0.2f};
    float scale = 8.0f;
    template <int N>
    Vec3<N> lookup(const Packet<N>& u, const Packet<N>& v, const Vec3<N>&) const {
        const Packet<N> s(scale);
        const Packet<N, int32_t> iu = toInt(floor(u * s)), iv = toInt(floor(v * s));
        const Mask<N> odd = ((iu + iv) & Packet<N, int32_t>(1)) != Packet<N, int32_t>(0);
        return select(odd, Vec3<N>(b), Vec3<N>(a));
    }
};
static_assert(Texture<CheckerTexture>);

struct ImageTexture {
    std::shared_ptr<const Image> image;

    Vec3f texel(int x, int y) const {
        const Image& im = *image;
        x = ((x % im.width) + im.width) % im.width;
        y = ((y % im.height) + im.height) % im.height;
        Vec3f c;
        for (int ch = 0; ch < 3; ++ch) c[ch] = im.at(x, y, std::min(ch, im.channels - 1));
        return c;
    }
    // Bilinear, v = 0 at the bottom of the image (OBJ convention).
    Vec3f sample(float u, float v) const {
        const float x = u * float(image->width) - 0.5f, y = (1.0f - v) * float(image->height) - 0.5f;
        const float fx = std::floor(x), fy = std::floor(y);
        const float tx = x - fx, ty = y - fy;
        const int ix = int(fx), iy = int(fy);
        return (texel(ix, iy) * (1 - tx) + texel(ix + 1, iy) * tx) * (1 - ty) +
               (texel(ix, iy + 1) * (1 - tx) + texel(ix + 1, iy + 1) * tx) * ty;
    }
    template <int N>
    Vec3<N> lookup(const Packet<N>& u, const Packet<N>& v, const Vec3<N>&) const {
        Vec3<N> r;
        for (int i = 0; i < N; ++i) r.setLane(i, sample(u[i], v[i]));
        return r;
    }
};
static_assert(Texture<ImageTexture>);

}  // namespace rtfact::surfaces
