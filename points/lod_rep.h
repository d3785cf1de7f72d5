// LoDRepSum: area-weighted sums over a subtree of discs (centre, normal, colour, bounds,
// height), from which the LoD structures make the subtree's representative disc: the
// area-weighted centre, normal and colour, with a radius that covers the subtree.
#pragma once
#include <algorithm>

#include "points/disc.h"

namespace rtfact::points {

struct LoDRepSum {
    double w = 0;
    double c[3] = {0, 0, 0};
    double n[3] = {0, 0, 0};
    double col[3] = {0, 0, 0};
    AABB box;        // bounds of all discs
    int height = 0;  // leaf = 1

    // One input disc (its normal decoded once: the bounds use it too).
    void add(const Disc& d) {
        const double wt = double(d.radius) * d.radius + 1e-30;
        const Vec3f nn = d.n(), cl = unpackRGB(d.rgba);
        for (int k = 0; k < 3; ++k) {
            c[k] += wt * d.center[k];
            n[k] += wt * nn[k];
            col[k] += wt * cl[k];
        }
        w += wt;
        box.extend(Disc::bounds(d.center, d.radius, nn));
    }
    void add(const LoDRepSum& o) {
        w += o.w;
        for (int k = 0; k < 3; ++k) {
            c[k] += o.c[k];
            n[k] += o.n[k];
            col[k] += o.col[k];
        }
        box = merge(box, o.box);
        height = std::max(height, o.height);
    }
    // The representative disc with radius 0 (the caller covers the subtree).
    Disc rep() const {
        Disc r;
        const double iw = w > 0 ? 1.0 / w : 0.0;
        r.center = Vec3f(float(c[0] * iw), float(c[1] * iw), float(c[2] * iw));
        const Vec3f nn{float(n[0]), float(n[1]), float(n[2])};
        const float len = length(nn);
        r.normal = encodeNormal(len > 0 ? nn / len : Vec3f(0, 0, 1));
        r.rgba =
            packRGBA(Vec3f(float(col[0] * iw), float(col[1] * iw), float(col[2] * iw)), uint8_t(std::min(height, 255)));
        return r;
    }
};

// Radius of the sphere around c that holds the box b: the farthest corner. Often much
// tighter than covering the children's spheres, whose slack compounds level by level.
inline float boxCoverRadius(Vec3f c, const AABB& b) { return length(vmax(b.hi - c, c - b.lo)); }

// Margin on covering radii: covers the padding of Disc::bounds().
inline float coverMargin(float r) { return r * 1.002f + 1e-7f; }

}  // namespace rtfact::points
