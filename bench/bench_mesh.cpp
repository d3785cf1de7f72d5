// rtfact-bench mesh FILE: RTfact's mesh tracers (the binary packet BVH, and the wide BVH
// with its packet traversal, `_wide` figures) against Embree 3 on the same
// triangles, camera and thread count, in one process. Primary rays (eyelight: nearest
// hit plus a normal lookup) and one shadow ray per hit towards a point light. Embree
// runs in its best packet mode for coherent rays: rtcIntersect16/rtcOccluded16 on 4x4
// pixel blocks with the coherent context flag and a medium-quality build.
// Secondary rays: AO-style occlusion rays and diffuse-bounce nearest-hit rays from the
// primary hits in random cosine-weighted directions, traced by RTfact's packet BVH
// (packets of neighbouring pixels), RTfact's wide BVH one ray at a time, and Embree's
// rtcOccluded1/rtcIntersect1 (incoherent context), all on the same ray list.
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <thread>

#include "bench/bench_commands.h"
#include "bench/bench_common.h"
#include "bench/bench_embree.h"
#include "core/render/ao_integrator.h"
#include "core/render/pinhole_camera.h"
#include "core/render/random.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/util/error.h"
#include "engine/built_scene.h"
#include "surfaces/mesh_scene.h"

namespace rtfact::bench {

using namespace rtfact::surfaces;
namespace {

// CPU ms of the whole process (every thread), for the cost of a multi-threaded build.
double processCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

// What both tracers produce per pixel, so their results can be compared.
struct Frame {
    int w, h;
    std::vector<float> t;      // nearest hit distance (inf: miss)
    std::vector<float> shade;  // eyelight value
    std::vector<uint8_t> lit;  // shadow result: 1 = light visible
    std::vector<int32_t> id;   // triangle hit (-1: miss)
    Frame(int w_, int h_)
        : w(w_), h(h_), t(size_t(w_) * h_), shade(size_t(w_) * h_), lit(size_t(w_) * h_), id(size_t(w_) * h_, -1) {}
};

struct Setup {
    PinholeCamera cam;
    Vec3f light;
    std::vector<Vec3f> triNormal;  // unit geometric normal per input triangle
};

// ---- RTfact ---------------------------------------------------------------------------

template <int N>
struct RTfactSide {
    static constexpr int bw = packetBlockWidth(N), bh = N / bw;
    const MeshScene<BVH<Triangle>>& scene;
    const Setup& s;

    void pixels(int x0, int y0, Packet<N>& px, Packet<N>& py) const { blockPixels<N, bw>(x0, y0, 0.5f, 0.5f, px, py); }
    // wide: the packet's rays go one by one through the wide BVH (far views with
    // sub-pixel triangles, where packets no longer share nodes).
    void primaryTile(Frame& f, int tx, int ty, bool wide = false) const {
        for (int y = ty; y < std::min(ty + kTile, f.h); y += bh)
            for (int x = tx; x < std::min(tx + kTile, f.w); x += bw) {
                Packet<N> px, py;
                pixels(x, y, px, py);
                RayPacket<N> rays;
                s.cam.template generate<N>(px, py, rays);
                const auto hit = wide ? scene.template intersectIncoherent<N>(rays, Mask<N>(true))
                                      : scene.template intersect<N>(rays, Mask<N>(true));
                for (int i = 0; i < N; ++i) {
                    const size_t pix = size_t(y + i / bw) * f.w + size_t(x + i % bw);
                    const int id = hit.id[i];
                    f.t[pix] = id >= 0 ? hit.t[i] : kInfinity;
                    f.id[pix] = id;
                    f.shade[pix] = id >= 0 ? std::fabs(dot(s.triNormal[size_t(id)], rays.dir.lane(i))) : 0.0f;
                }
            }
    }
    // Shadow rays start at the light and end just before the hit point, so a packet
    // shares its origin (the same segments as surface-to-light rays).
    void shadowTile(Frame& f, const Frame& primary, int tx, int ty) const {
        for (int y = ty; y < std::min(ty + kTile, f.h); y += bh)
            for (int x = tx; x < std::min(tx + kTile, f.w); x += bw) {
                Packet<N> px, py;
                pixels(x, y, px, py);
                RayPacket<N> cam;
                s.cam.template generate<N>(px, py, cam);
                Packet<N> t;
                for (int i = 0; i < N; ++i) t[i] = primary.t[size_t(y + i / bw) * f.w + size_t(x + i % bw)];
                const Mask<N> active = t < Packet<N>(kInfinity);
                if (none(active)) continue;
                const Vec3<N> p = cam.org + cam.dir * select(active, t, Packet<N>(0.0f));
                RayPacket<N> sh;
                sh.org = Vec3<N>(s.light);
                const Vec3<N> d = p - sh.org;
                const Packet<N> dist = length(d);
                sh.dir = d * rcp(max(dist, Packet<N>(1e-30f)));
                sh.tMin = Packet<N>(0.0f);
                sh.tMax = dist * Packet<N>(1.0f - 1e-4f);
                sh.commonOrigin = true;
                sh.finalize();
                const Mask<N> occ = scene.template occluded<N>(sh, active);
                for (int i = 0; i < N; ++i)
                    if (active[i]) f.lit[size_t(y + i / bw) * f.w + size_t(x + i % bw)] = occ[i] ? 0 : 1;
            }
    }
};

// ---- Secondary rays ----------------------------------------------------------------------

// Random cosine-weighted rays from the primary hits, `samples` per hit, grouped so that
// consecutive rays of one packet start at neighbouring pixels (as in the AO integrator).
struct SecondaryRays {
    std::vector<Vec3f> org, dir;
    float tMaxAO = kInfinity;
    size_t size() const { return org.size(); }
};

SecondaryRays makeSecondary(const Frame& base, const Setup& s, const AABB& box, int samples, int group) {
    SecondaryRays r;
    const float diag = std::max(length(box.extent()), 1e-6f);
    r.tMaxAO = 0.2f * diag;
    std::vector<size_t> hitPix;
    for (size_t i = 0; i < base.t.size(); ++i)
        if (base.id[i] >= 0) hitPix.push_back(i);
    for (size_t g = 0; g < hitPix.size(); g += size_t(group))
        for (int smp = 0; smp < samples; ++smp)
            for (size_t j = g; j < std::min(g + size_t(group), hitPix.size()); ++j) {
                const size_t pix = hitPix[j];
                const int px = int(pix % size_t(base.w)), py = int(pix / size_t(base.w));
                RayPacket<1> cam;
                s.cam.template generate<1>(Packet<1>(float(px) + 0.5f), Packet<1>(float(py) + 0.5f), cam);
                const Vec3f d0 = cam.dir.lane(0);
                Vec3f n = s.triNormal[size_t(base.id[pix])];
                if (dot(n, d0) > 0.0f) n = -n;
                const Vec3<1> dir = cosineHemisphere(Vec3<1>(n), hashToUnit<1>(px, py, uint32_t(smp), 0),
                                                     hashToUnit<1>(px, py, uint32_t(smp), 1));
                r.org.push_back(cam.org.lane(0) + d0 * base.t[pix] + n * (1e-4f * diag));
                r.dir.push_back(normalize(dir.lane(0)));
            }
    return r;
}

template <class F>
double timeRange(int threads, size_t n, size_t grain, F&& f) {
    return timeArena(threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain),
                          [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
    });
}

// How RTfact traces the secondary ray list: packets of N through the packet BVH, single
// rays through the wide BVH (one call per ray), or packets of N through the wide BVH's
// incoherent queries, which trace the lanes as interleaved single rays (as the AO and
// path integrators call them).
enum class SecondaryMode { Packet, WideSingle, WideGroup };

// RTfact on the secondary ray list. Results go to occ (AO) / t (bounce) for the
// agreement check.
template <int N>
void rtSecondary(const MeshScene<BVH<Triangle>>& scene, const SecondaryRays& sr, size_t b, size_t e, SecondaryMode mode,
                 bool ao, std::vector<float>& out) {
    if (mode == SecondaryMode::WideSingle) {
        for (size_t i = b; i < e; ++i) {
            RayPacket<1> r;
            r.setLane(0, sr.org[i], sr.dir[i], 0.0f, ao ? sr.tMaxAO : kInfinity);
            r.finalize();
            if (ao) {
                out[i] = scene.occludedIncoherent<1>(r, Mask<1>(true))[0] ? 1.0f : 0.0f;
            } else {
                const auto h = scene.intersectIncoherent<1>(r, Mask<1>(true));
                out[i] = int32_t(h.id) >= 0 ? float(h.t) : kInfinity;
            }
        }
        return;
    }
    const bool wide = mode == SecondaryMode::WideGroup;
    for (size_t p = b; p < e; p += N) {
        RayPacket<N> r;
        Mask<N> active(true);
        for (int i = 0; i < N; ++i) {
            const size_t k = p + size_t(i);
            if (k < e)
                r.setLane(i, sr.org[k], sr.dir[k], 0.0f, ao ? sr.tMaxAO : kInfinity);
            else
                r.setLane(i, sr.org[b], sr.dir[b], 0.0f, 0.0f), active.set(i, false);
        }
        r.finalize();
        if (ao) {
            const Mask<N> occ =
                wide ? scene.template occludedIncoherent<N>(r, active) : scene.template occluded<N>(r, active);
            for (int i = 0; i < N && p + size_t(i) < e; ++i) out[p + size_t(i)] = occ[i] ? 1.0f : 0.0f;
        } else {
            const auto h =
                wide ? scene.template intersectIncoherent<N>(r, active) : scene.template intersect<N>(r, active);
            for (int i = 0; i < N && p + size_t(i) < e; ++i) out[p + size_t(i)] = h.id[i] >= 0 ? h.t[i] : kInfinity;
        }
    }
}

// Secondary rays one by one through a given wide tree (layout variants of the wide BVH).
template <class Tree>
void wideSecondary(const Tree& w, const SecondaryRays& sr, size_t b, size_t e, bool ao, std::vector<float>& out) {
    const WideBVHIntersector<TriangleIntersector> isect;
    for (size_t i = b; i < e; ++i) {
        RayPacket<1> r;
        r.setLane(0, sr.org[i], sr.dir[i], 0.0f, ao ? sr.tMaxAO : kInfinity);
        r.finalize();
        if (ao) {
            out[i] = isect.occluded<false>(w, r, Mask<1>(true))[0] ? 1.0f : 0.0f;
        } else {
            TriangleIntersector::Hit<1> h;
            isect.intersect<false, HitData::Shading>(w, r, h, Mask<1>(true));
            out[i] = int32_t(h.id) >= 0 ? float(h.t) : kInfinity;
        }
    }
}

// Arity K and leaf block L of the wide BVH against the default (kMeshWideArity,
// kMeshLeafBlock): build time and AO / bounce throughput, as ratios to Embree's figures.
template <int K, int L>
void wideVariant(const Mesh& mesh, const SecondaryRays& sr, const std::vector<int>& threadCounts, int repeat,
                 const double (*embreeMrays)[2]) {
    WideSAHBVHBuilder b;
    b.leafBlock = L;
    b.maxLeafSize = 4 * L;
    const auto t0 = Clock::now();
    WideBVHTopology<K> topo;
    const std::vector<AABB> bounds = meshTriangleBounds(mesh);
    b.build(std::span<const AABB>(bounds), topo);
    const auto w =
        packLeafBlocks<TriangleBlock<L>>(std::move(topo), [&](TriangleBlock<L>& blk, const uint32_t* ids, int n) {
            blk.fill(ids, n, [&](uint32_t t) {
                return Triangle{mesh.positions[mesh.indices[3 * t]], mesh.positions[mesh.indices[3 * t + 1]],
                                mesh.positions[mesh.indices[3 * t + 2]]};
            });
        });
    const double buildMs = msSince(t0);
    std::vector<float> out(sr.size());
    for (size_t ti = 0; ti < threadCounts.size(); ++ti) {
        const int T = threadCounts[ti];
        double ms[2] = {1e30, 1e30};
        for (int r = 0; r < repeat; ++r)
            for (int ao = 0; ao < 2; ++ao)
                ms[ao] = std::min(ms[ao], timeRange(T, sr.size(), 16384, [&](size_t bb, size_t en) {
                                      wideSecondary(w, sr, bb, en, ao != 0, out);
                                  }));
        const double aoM = double(sr.size()) / (ms[1] * 1000.0), bnM = double(sr.size()) / (ms[0] * 1000.0);
        std::printf(
            "wide_variant K=%d block=%d threads=%d build_ms_all_threads=%.2f memory_bytes=%zu ao_mrays=%.2f "
            "bounce_mrays=%.2f ratio_ao_vs_embree=%.3f ratio_bounce_vs_embree=%.3f\n",
            K, L, T, buildMs, w.memoryBytes(), aoM, bnM, aoM / embreeMrays[ti][1], bnM / embreeMrays[ti][0]);
    }
}

// ---- Embree -----------------------------------------------------------------------------

struct EmbreeSide {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    const Setup& s;

    EmbreeSide(const Setup& setup, int threads) : s(setup) { device = newEmbreeDevice(threads); }
    ~EmbreeSide() {
        if (scene) rtcReleaseScene(scene);
        rtcReleaseDevice(device);
    }
    double lastCpuMs = 0.0;      // the calling thread's CPU ms of the last build
    double lastProcessMs = 0.0;  // the process's CPU ms of the last build (all threads)
    // Returns build ms (buffer copy excluded: both sides start from the loaded mesh).
    // robust: RTC_SCENE_FLAG_ROBUST, Embree's watertight mode (its default test may miss
    // at shared edges; RTfact's triangle tests are always watertight).
    double build(const Mesh& m, bool robust = false) {
        if (scene) rtcReleaseScene(scene);
        gEmbreeBytes = 0;  // counts what this scene allocates
        scene = rtcNewScene(device);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
        rtcSetSceneFlags(scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_MEDIUM);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), m.positions.size()));
        for (size_t i = 0; i < m.positions.size(); ++i) {
            v[3 * i] = m.positions[i].x;
            v[3 * i + 1] = m.positions[i].y;
            v[3 * i + 2] = m.positions[i].z;
        }
        auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(uint32_t), m.triangles()));
        std::copy(m.indices.begin(), m.indices.end(), idx);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        const auto t0 = Clock::now();
        const double c0 = threadCpuMs(), p0 = processCpuMs();
        rtcCommitScene(scene);
        lastCpuMs = threadCpuMs() - c0;
        lastProcessMs = processCpuMs() - p0;
        return msSince(t0);
    }

    static void pixels(int x0, int y0, Packet<16>& px, Packet<16>& py) {
        blockPixels<16, 4>(x0, y0, 0.5f, 0.5f, px, py);
    }
    void primaryTile(Frame& f, int tx, int ty) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        alignas(64) int valid[16];
        std::fill(valid, valid + 16, -1);
        for (int y = ty; y < std::min(ty + kTile, f.h); y += 4)
            for (int x = tx; x < std::min(tx + kTile, f.w); x += 4) {
                Packet<16> px, py;
                pixels(x, y, px, py);
                RayPacket<16> rays;
                s.cam.generate<16>(px, py, rays);
                RTCRayHit16 rh;
                toEmbree(rays, rh);
                rtcIntersect16(valid, scene, &ctx, &rh);
                for (int i = 0; i < 16; ++i) {
                    const size_t pix = size_t(y + i / 4) * f.w + size_t(x + i % 4);
                    const bool h = rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
                    f.t[pix] = h ? rh.ray.tfar[i] : kInfinity;
                    f.shade[pix] = h ? std::fabs(dot(s.triNormal[rh.hit.primID[i]], rays.dir.lane(i))) : 0.0f;
                }
            }
    }
    // fromLight: the same light-to-point segments as RTfact; else point-to-light rays.
    void shadowTile(Frame& f, const Frame& primary, int tx, int ty, bool fromLight) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        alignas(64) int valid[16];
        for (int y = ty; y < std::min(ty + kTile, f.h); y += 4)
            for (int x = tx; x < std::min(tx + kTile, f.w); x += 4) {
                Packet<16> px, py;
                pixels(x, y, px, py);
                RayPacket<16> cam;
                s.cam.generate<16>(px, py, cam);
                RTCRay16 r;
                bool any = false;
                for (int i = 0; i < 16; ++i) {
                    const float t = primary.t[size_t(y + i / 4) * f.w + size_t(x + i % 4)];
                    valid[i] = t < kInfinity ? -1 : 0;
                    any |= valid[i] != 0;
                    const Vec3f p = cam.org.lane(i) + cam.dir.lane(i) * (valid[i] ? t : 0.0f);
                    const Vec3f d = fromLight ? p - s.light : s.light - p;
                    const float dist = std::max(length(d), 1e-30f);
                    const Vec3f o = fromLight ? s.light : p;
                    r.org_x[i] = o.x;
                    r.org_y[i] = o.y;
                    r.org_z[i] = o.z;
                    r.dir_x[i] = d.x / dist;
                    r.dir_y[i] = d.y / dist;
                    r.dir_z[i] = d.z / dist;
                    // Surface-to-light rays skip their own surface with a relative offset.
                    r.tnear[i] = fromLight ? 0.0f : 1e-4f * dist;
                    r.tfar[i] = fromLight ? dist * (1.0f - 1e-4f) : dist;
                    r.time[i] = 0.0f;
                    r.mask[i] = ~0u;
                    r.flags[i] = 0;
                }
                if (!any) continue;
                rtcOccluded16(valid, scene, &ctx, &r);
                for (int i = 0; i < 16; ++i)
                    if (valid[i]) f.lit[size_t(y + i / 4) * f.w + size_t(x + i % 4)] = r.tfar[i] < 0.0f ? 0 : 1;
            }
    }
};

void embreeSecondary(RTCScene scene, const SecondaryRays& sr, size_t b, size_t e, bool ao, std::vector<float>& out) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    for (size_t i = b; i < e; ++i) {
        RTCRayHit rh;
        rh.ray.org_x = sr.org[i].x;
        rh.ray.org_y = sr.org[i].y;
        rh.ray.org_z = sr.org[i].z;
        rh.ray.dir_x = sr.dir[i].x;
        rh.ray.dir_y = sr.dir[i].y;
        rh.ray.dir_z = sr.dir[i].z;
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = ao ? sr.tMaxAO : kInfinity;
        rh.ray.time = 0.0f;
        rh.ray.mask = ~0u;
        rh.ray.flags = 0;
        rh.ray.id = 0;
        if (ao) {
            rtcOccluded1(scene, &ctx, &rh.ray);
            out[i] = rh.ray.tfar < 0.0f ? 1.0f : 0.0f;
        } else {
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(scene, &ctx, &rh);
            out[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar : kInfinity;
        }
    }
}

struct Result {
    double ms = 1e30;
    uint64_t rays = 0;
    double mrays() const { return double(rays) / (ms * 1000.0); }
};

uint64_t countHits(const Frame& f) {
    return uint64_t(std::count_if(f.t.begin(), f.t.end(), [](float t) { return t < kInfinity; }));
}

// Wide packet traversal tuning from the command line (negative: the library's default).
struct WideTuning {
    float singleNode = -1.0f, singleLeaf = -1.0f;
    int packetSplit = -1;
};

template <int N>
int run(const std::string& file, const Mesh& mesh, const Setup& setup, int w, int h, int allThreads, int repeat,
        int secSamples, bool wideVariants, const WideTuning& tune, bool buildOnly) {
    std::printf("cpu: %s, isa %s (Embree capped at %s)\n", cpuModel().c_str(), simd::isaName(), embreeMaxIsa());
    std::printf("file=%s\ntriangles=%zu\nimage=%dx%d\npacket=%d\nthreads_all=%d\n", file.c_str(), mesh.triangles(), w,
                h, N, allThreads);
    auto meshPtr = std::make_shared<const Mesh>(mesh);
    const std::vector<int> threadCounts = allThreads > 1 ? std::vector<int>{1, allThreads} : std::vector<int>{1};
    // RTfact's wide BVH alone (packet traversal for primary and shadow rays, single rays
    // for secondaries: the renderer's mesh scene), and the binary packet BVH that
    // `--secondary packet` builds instead (its build, memory and packet traversal; the
    // `rtfact=` / `ratio=` figures).
    MeshScene<BVH<Triangle>> scene, pscene;
    scene.mesh = pscene.mesh = meshPtr;
    scene.packetBVHMaxTriangles = 0;  // the wide BVH alone
    pscene.buildWide = false;
    if (tune.singleNode >= 0.0f) scene.widePacketTracer.isect.singleRayFraction = tune.singleNode;
    if (tune.singleLeaf >= 0.0f) scene.widePacketTracer.isect.singleRayLeafFraction = tune.singleLeaf;
    if (tune.packetSplit >= 0) scene.widePacketTracer.isect.packetSplit = tune.packetSplit;
    double rtBuild[2] = {1e30, 1e30}, emBuild[2] = {1e30, 1e30}, packetBuild[2] = {1e30, 1e30};
    double rtCpu = 1e30, emCpu = 1e30;  // 1-thread builds: CPU ms of the thread running them
    // Builds at the most threads: CPU ms of the whole process (all threads; a parallel
    // path that does more work than the serial one shows here, whatever the load).
    double rtProc = 1e30, emProc = 1e30;
    std::unique_ptr<EmbreeSide> em;
    for (size_t ti = 0; ti < threadCounts.size(); ++ti) {
        const int T = threadCounts[ti];
        em = std::make_unique<EmbreeSide>(setup, T);
        for (int r = 0; r < repeat; ++r) {
            tbb::task_arena arena(T);
            const auto t0 = Clock::now();
            const double c0 = threadCpuMs(), p0 = processCpuMs();
            arena.execute([&] { scene.build(); });
            rtBuild[ti] = std::min(rtBuild[ti], msSince(t0));
            if (T == 1) rtCpu = std::min(rtCpu, threadCpuMs() - c0);
            if (T > 1) rtProc = std::min(rtProc, processCpuMs() - p0);
            arena.execute([&] { emBuild[ti] = std::min(emBuild[ti], em->build(mesh)); });
            if (T == 1) emCpu = std::min(emCpu, em->lastCpuMs);
            if (T > 1) emProc = std::min(emProc, em->lastProcessMs);
            if (buildOnly) continue;
            const auto t1 = Clock::now();
            arena.execute([&] { pscene.build(); });
            packetBuild[ti] = std::min(packetBuild[ti], msSince(t1));
        }
        if (buildOnly)
            std::printf("build_ms_threads%d: rtfact_wide=%.2f embree=%.2f ratio_wide=%.3f\n", T, rtBuild[ti],
                        emBuild[ti], rtBuild[ti] / emBuild[ti]);
        else
            std::printf("build_ms_threads%d: rtfact=%.2f rtfact_wide=%.2f embree=%.2f ratio=%.3f ratio_wide=%.3f\n", T,
                        packetBuild[ti], rtBuild[ti], emBuild[ti], packetBuild[ti] / emBuild[ti],
                        rtBuild[ti] / emBuild[ti]);
    }
    std::printf("build_cpu_ms_threads1: rtfact_wide=%.2f embree=%.2f ratio_wide=%.3f\n", rtCpu, emCpu, rtCpu / emCpu);
    if (allThreads > 1)
        std::printf("build_cpu_ms_threads%d: rtfact_wide=%.2f embree=%.2f ratio_wide=%.3f (process CPU, all threads)\n",
                    allThreads, rtProc, emProc, rtProc / emProc);
    if (buildOnly) {
        // Only the wide BVH's build against Embree's (profiling the builder).
        const size_t last = threadCounts.size() - 1;
        std::printf("memory_bytes: rtfact_wide=%zu embree=%zu\nratio_build_wide=%.3f\n", scene.memoryBytes(),
                    size_t(gEmbreeBytes.load()), rtBuild[last] / emBuild[last]);
        return 0;
    }
    const double wideBytes = double(scene.memoryBytes()), rtBytes = double(pscene.memoryBytes()),
                 emBytes = double(gEmbreeBytes.load());
    std::printf("memory_bytes: rtfact=%.0f rtfact_wide=%.0f embree=%.0f ratio_memory=%.3f ratio_memory_wide=%.3f\n",
                rtBytes, wideBytes, emBytes, rtBytes / std::max(emBytes, 1.0), wideBytes / std::max(emBytes, 1.0));

    RTfactSide<N> rt{scene, setup}, rtp{pscene, setup};
    Frame fr(w, h), fe(w, h), fp(w, h), base(w, h);
    // Reference primary hits for the shadow pass, shared by both sides.
    timeTiles(allThreads, w, h, [&](int x, int y) { rt.primaryTile(base, x, y); });
    const uint64_t hits = countHits(base);
    std::printf("primary_hits=%llu\n", (unsigned long long)hits);
    double worstPrimary = 1e30, worstShadow = 1e30, worstPrimaryWide = 1e30, worstShadowWide = 1e30;
    for (int T : threadCounts) {
        Result rp, ep, rs, es, esSurf, pp, ps;
        for (int r = 0; r < repeat; ++r) {
            rp.ms = std::min(rp.ms, timeTiles(T, w, h, [&](int x, int y) { rt.primaryTile(fr, x, y); }));
            ep.ms = std::min(ep.ms, timeTiles(T, w, h, [&](int x, int y) { em->primaryTile(fe, x, y); }));
            pp.ms = std::min(pp.ms, timeTiles(T, w, h, [&](int x, int y) { rtp.primaryTile(fp, x, y); }));
            rs.ms = std::min(rs.ms, timeTiles(T, w, h, [&](int x, int y) { rt.shadowTile(fr, base, x, y); }));
            esSurf.ms =
                std::min(esSurf.ms, timeTiles(T, w, h, [&](int x, int y) { em->shadowTile(fe, base, x, y, false); }));
            es.ms = std::min(es.ms, timeTiles(T, w, h, [&](int x, int y) { em->shadowTile(fe, base, x, y, true); }));
            ps.ms = std::min(ps.ms, timeTiles(T, w, h, [&](int x, int y) { rtp.shadowTile(fp, base, x, y); }));
        }
        rp.rays = ep.rays = pp.rays = uint64_t(w) * h;
        rs.rays = es.rays = esSurf.rays = ps.rays = hits;
        // Embree's better shadow orientation is the peer.
        const Result& esBest = es.ms <= esSurf.ms ? es : esSurf;
        // rtfact: the binary packet BVH (the renderer's); rtfact_wide: the wide BVH's
        // packet traversal.
        std::printf(
            "threads=%d primary_mrays: rtfact=%.2f rtfact_wide=%.2f embree=%.2f ratio=%.3f ratio_wide=%.3f "
            "wide_vs_packet_bvh=%.3f\n",
            T, pp.mrays(), rp.mrays(), ep.mrays(), pp.mrays() / ep.mrays(), rp.mrays() / ep.mrays(),
            rp.mrays() / pp.mrays());
        std::printf(
            "threads=%d shadow_mrays: rtfact=%.2f rtfact_wide=%.2f embree=%.2f (from light %.2f, to light %.2f) "
            "ratio=%.3f ratio_wide=%.3f wide_vs_packet_bvh=%.3f\n",
            T, ps.mrays(), rs.mrays(), esBest.mrays(), es.mrays(), esSurf.mrays(), ps.mrays() / esBest.mrays(),
            rs.mrays() / esBest.mrays(), rs.mrays() / ps.mrays());
        worstPrimary = std::min(worstPrimary, pp.mrays() / ep.mrays());
        worstShadow = std::min(worstShadow, ps.mrays() / esBest.mrays());
        worstPrimaryWide = std::min(worstPrimaryWide, rp.mrays() / ep.mrays());
        worstShadowWide = std::min(worstShadowWide, rs.mrays() / esBest.mrays());
    }
    // The same primary rays one by one through the wide BVH (not part of the ratios):
    // what the packet traversal's single-ray hand-over can reach on far views.
    // And the packet traversal with every chunk starting at the root (packetSplit 0):
    // what the whole packet's traversal of the top levels gains.
    const int split = scene.widePacketTracer.isect.packetSplit;
    for (int T : threadCounts) {
        Result rw, rp, r0;
        Frame fw(w, h);
        for (int r = 0; r < repeat; ++r) {
            rp.ms = std::min(rp.ms, timeTiles(T, w, h, [&](int x, int y) { rt.primaryTile(fw, x, y, false); }));
            rw.ms = std::min(rw.ms, timeTiles(T, w, h, [&](int x, int y) { rt.primaryTile(fw, x, y, true); }));
            scene.widePacketTracer.isect.packetSplit = 0;
            r0.ms = std::min(r0.ms, timeTiles(T, w, h, [&](int x, int y) { rt.primaryTile(fw, x, y, false); }));
            scene.widePacketTracer.isect.packetSplit = split;
        }
        rw.rays = rp.rays = r0.rays = uint64_t(w) * h;
        std::printf(
            "threads=%d primary_mrays: rtfact_wide_packet=%.2f rtfact_wide_single=%.2f ratio_single_vs_packet=%.3f "
            "rtfact_wide_from_root=%.2f ratio_packet_vs_from_root=%.3f (packet split %d)\n",
            T, rp.mrays(), rw.mrays(), rw.mrays() / rp.mrays(), r0.mrays(), rp.mrays() / r0.mrays(), split);
    }
    // Secondary rays (incoherent): the same list for every tracer.
    if (secSamples > 0) {
        const SecondaryRays sr = makeSecondary(base, setup, scene.bounds(), secSamples, N);
        std::printf("secondary_rays=%zu (%d per primary hit, AO length %.4g)\n", sr.size(), secSamples, sr.tMaxAO);
        std::vector<float> outP(sr.size()), outW(sr.size()), outG(sr.size()), outE(sr.size()), outR(sr.size());
        double embreeMrays[2][2] = {{0, 0}, {0, 0}};  // [thread count index][ao]
        // Embree in its watertight mode as well: the like-for-like peer of RTfact's test.
        EmbreeSide robust(setup, threadCounts.back());
        {
            tbb::task_arena arena(threadCounts.back());
            arena.execute([&] { robust.build(mesh, true); });
        }
        for (int ao = 1; ao >= 0; --ao) {
            const char* name = ao ? "ao_occluded" : "bounce_nearest";
            for (size_t ti = 0; ti < threadCounts.size(); ++ti) {
                const int T = threadCounts[ti];
                Result p, wd, wg, e, er;
                auto timeMode = [&](Result& res, const MeshScene<BVH<Triangle>>& sc, SecondaryMode m,
                                    std::vector<float>& out) {
                    res.ms = std::min(res.ms, timeRange(T, sr.size(), size_t(N) * 64, [&](size_t b, size_t en) {
                                          rtSecondary<N>(sc, sr, b, en, m, ao, out);
                                      }));
                };
                for (int r = 0; r < repeat; ++r) {
                    timeMode(p, pscene, SecondaryMode::Packet, outP);
                    timeMode(wd, scene, SecondaryMode::WideSingle, outW);
                    timeMode(wg, scene, SecondaryMode::WideGroup, outG);
                    e.ms = std::min(e.ms, timeRange(T, sr.size(), size_t(N) * 64, [&](size_t b, size_t en) {
                                        embreeSecondary(em->scene, sr, b, en, ao, outE);
                                    }));
                    er.ms = std::min(er.ms, timeRange(T, sr.size(), size_t(N) * 64, [&](size_t b, size_t en) {
                                         embreeSecondary(robust.scene, sr, b, en, ao, outR);
                                     }));
                }
                p.rays = wd.rays = wg.rays = e.rays = er.rays = sr.size();
                embreeMrays[ti][ao] = e.mrays();
                std::printf(
                    "threads=%d %s_mrays: rtfact_wide_single=%.2f rtfact_wide_group=%.2f rtfact_packet%d=%.2f "
                    "embree_single=%.2f embree_robust_single=%.2f ratio_wide_vs_embree=%.3f "
                    "ratio_wide_vs_embree_robust=%.3f ratio_group_vs_embree=%.3f ratio_wide_vs_packet=%.3f\n",
                    T, name, wd.mrays(), wg.mrays(), N, p.mrays(), e.mrays(), er.mrays(), wd.mrays() / e.mrays(),
                    wd.mrays() / er.mrays(), wg.mrays() / e.mrays(), wd.mrays() / p.mrays());
            }
            size_t diffPW = 0, diffWE = 0, diffWG = 0, diffWR = 0;
            for (size_t i = 0; i < sr.size(); ++i) {
                const auto same = [&](float a, float b) {
                    return ao ? a == b
                              : (std::isinf(a) == std::isinf(b) &&
                                 (std::isinf(a) || std::fabs(a - b) <= 1e-3f * std::max(1.0f, a)));
                };
                diffPW += !same(outP[i], outW[i]);
                diffWE += !same(outW[i], outE[i]);
                diffWR += !same(outW[i], outR[i]);
                diffWG += outW[i] != outG[i];  // the same traversal per ray: bit-exact
            }
            std::printf(
                "agreement_%s: packet_vs_wide_diff=%zu wide_vs_embree_diff=%zu wide_vs_embree_robust_diff=%zu "
                "wide_vs_group_diff=%zu\n",
                name, diffPW, diffWE, diffWR, diffWG);
        }
        if (wideVariants) {
            wideVariant<8, 4>(mesh, sr, threadCounts, repeat, embreeMrays);
            wideVariant<8, 8>(mesh, sr, threadCounts, repeat, embreeMrays);
            if constexpr (simd::kNativeWidth >= 16) {
                wideVariant<16, 4>(mesh, sr, threadCounts, repeat, embreeMrays);
                wideVariant<16, 8>(mesh, sr, threadCounts, repeat, embreeMrays);
            }
        }
    }
    // Agreement of the tracers (a sanity check, not a timing).
    size_t hitDiff = 0, rtOnlyShadow = 0, emOnlyShadow = 0, packetDiff = 0;
    for (size_t i = 0; i < fr.t.size(); ++i) {
        hitDiff += (fr.t[i] < kInfinity) != (fe.t[i] < kInfinity);
        packetDiff += fr.id[i] != fp.id[i] || fr.lit[i] != fp.lit[i];
        if (base.t[i] == kInfinity) continue;
        rtOnlyShadow += !fr.lit[i] && fe.lit[i];
        emOnlyShadow += fr.lit[i] && !fe.lit[i];
    }
    std::printf(
        "agreement: primary_hit_diff_pixels=%zu shadowed_only_by_rtfact=%zu shadowed_only_by_embree=%zu "
        "wide_vs_binary_packet_diff_pixels=%zu\n",
        hitDiff, rtOnlyShadow, emOnlyShadow, packetDiff);
    const int last = int(threadCounts.size()) - 1;
    std::printf(
        "ratio_primary=%.3f\nratio_shadow=%.3f\nratio_build=%.3f\nratio_memory=%.3f\nratio_primary_wide=%.3f\n"
        "ratio_shadow_wide=%.3f\nratio_build_wide=%.3f\nratio_memory_wide=%.3f\n",
        worstPrimary, worstShadow, packetBuild[last] / emBuild[last], rtBytes / std::max(emBytes, 1.0),
        worstPrimaryWide, worstShadowWide, rtBuild[last] / emBuild[last], wideBytes / std::max(emBytes, 1.0));
    std::printf(
        "(ratios: RTfact/Embree throughput, the worse of 1 and %d threads; build: RTfact/Embree time at %d threads, "
        "lower is better)\n",
        allThreads, threadCounts[last]);
    return 0;
}

}  // namespace

int benchMesh(int argc, char** argv) {
    CLI::App app{"RTfact vs Embree on a mesh: BVH build, primary and shadow rays", "rtfact-bench mesh"};
    std::string file, eye, at, up, size = "1024x1024";
    float fov = 45.0f;
    int threads = 0, packet = 256, repeat = 3, grid = 1, secondary = 4;
    bool wideVariants = false, buildOnly = false;
    WideTuning tune;
    app.add_option("FILE", file, "Mesh file")->required();
    app.add_option("--eye", eye, "Camera position x,y,z");
    app.add_option("--at", at, "Camera target x,y,z");
    app.add_option("--up", up, "Camera up x,y,z");
    app.add_option("--fov", fov, "Vertical field of view (degrees)")->capture_default_str();
    app.add_option("--threads", threads, "All-threads figure uses this many (0: all cores)")->capture_default_str();
    app.add_option("--size", size, "Image size WxH")->capture_default_str();
    app.add_option("--packet", packet, "RTfact packet size: 16, 64 or 256")
        ->capture_default_str()
        ->check(CLI::IsMember({16, 64, 256}));
    app.add_option("--grid", grid, "Many occluders: a GxG grid of copies of the mesh on a ground plane")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    app.add_option("--secondary", secondary, "Secondary (AO and bounce) rays per primary hit; 0: skip")
        ->capture_default_str()
        ->check(CLI::Range(0, 64));
    app.add_option("--repeat", repeat, "Runs per measurement (best is kept)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100));
    app.add_flag("--wide-variants", wideVariants,
                 "Also time wide BVH layouts (arity 8/16, leaf blocks of 4/8 triangles) on the secondary rays");
    app.add_flag("--build-only", buildOnly,
                 "Only time the wide BVH's build against Embree's (no binary packet BVH, no rays): for profiling");
    app.add_option("--single-lanes", tune.singleNode,
                   "Wide packet traversal: nodes reached by at most this fraction of a chunk's lanes continue as "
                   "single rays (tuning; default: the library's)")
        ->check(CLI::Range(0.0f, 1.0f));
    app.add_option("--single-lanes-leaf", tune.singleLeaf, "The same for leaves (tuning)")
        ->check(CLI::Range(0.0f, 1.0f));
    app.add_option("--packet-split", tune.packetSplit,
                   "Wide packet traversal: the whole packet splits nodes with at most this many candidate children "
                   "before its chunks go on alone; 0: chunks start at the root (tuning; default: the library's)")
        ->check(CLI::Range(0, 64));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return usageExit(app, e);
    }
    int w = 1024, h = 1024;
    if (std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 16384 || h > 16384 || w % 16 ||
        h % 16)
        throw Error("", "--size: expected WxH, multiples of 16 in 16..16384");
    // Loading (every format, several files merged) is the engine's, as for `rtfact mesh`.
    engine::OpenOptions oo;
    oo.kind = engine::SceneKind::Mesh;
    oo.progress = false;
    Mesh mesh = *engine::loadedMesh(engine::open({file}, oo));
    if (grid > 1) {
        // Copies side by side (shadowing each other) on a ground quad.
        const Mesh one = mesh;
        const AABB b = one.bounds();
        const Vec3f e = b.extent();
        const float step = 1.05f * std::max(e.x, e.z);
        for (int gz = 0; gz < grid; ++gz)
            for (int gx = 0; gx < grid; ++gx) {
                if (gx == 0 && gz == 0) continue;
                Mesh c = one;
                for (Vec3f& p : c.positions) p += Vec3f(float(gx) * step, 0.0f, float(gz) * step);
                mesh.append(c);
            }
        Mesh ground;
        const float lo = -step, hi = float(grid) * step;
        ground.positions = {{lo, b.lo.y, lo}, {hi, b.lo.y, lo}, {hi, b.lo.y, hi}, {lo, b.lo.y, hi}};
        ground.indices = {0, 2, 1, 0, 3, 2};
        ground.computeNormals();
        mesh.append(ground);
    }
    Setup setup;
    const AABB box = mesh.bounds();
    CameraFrame frame = fitCamera(box, fov, float(w) / float(h));
    if (!eye.empty()) frame.eye = parseVec(eye, "--eye");
    if (!at.empty()) frame.at = parseVec(at, "--at");
    if (!up.empty()) frame.up = parseVec(up, "--up");
    frame.fovDeg = fov;
    setup.cam = PinholeCamera(frame, w, h);
    // The light sits above and beside the camera, so shadows fall visibly.
    const float r = length(box.extent());
    setup.light = frame.eye + normalize(frame.up) * r - normalize(cross(frame.at - frame.eye, frame.up)) * (0.7f * r);
    setup.triNormal.resize(mesh.triangles());
    for (size_t i = 0; i < mesh.triangles(); ++i) {
        const Vec3f a = mesh.positions[mesh.indices[3 * i]], b = mesh.positions[mesh.indices[3 * i + 1]],
                    c = mesh.positions[mesh.indices[3 * i + 2]];
        setup.triNormal[i] = normalize(cross(b - a, c - a));
    }
    const int all = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
    if (packet == 16) return run<16>(file, mesh, setup, w, h, all, repeat, secondary, wideVariants, tune, buildOnly);
    if (packet == 64) return run<64>(file, mesh, setup, w, h, all, repeat, secondary, wideVariants, tune, buildOnly);
    return run<256>(file, mesh, setup, w, h, all, repeat, secondary, wideVariants, tune, buildOnly);
}

}  // namespace rtfact::bench
