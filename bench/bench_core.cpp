// Micro-benchmarks of the core: SIMD kernels and sphere-scene traversal throughput at
// packet sizes 1, 4, 16, 64 and 256 (primary rays, common origin, one thread).
#include <benchmark/benchmark.h>

#include "core/accel/ray_box.h"
#include "core/geometry/sphere_scene.h"
#include "core/render/pinhole_camera.h"
#include "core/render/ray_tracing_renderer.h"

using namespace rtfact;

namespace {

template <int N>
void BM_PacketFma(benchmark::State& state) {
    Packet<N> a = Packet<N>::ramp(1.0f, 0.001f), b(1.0001f), c(0.5f);
    for (auto _ : state) {
        for (int i = 0; i < 64; ++i) a = a * b + c;
        benchmark::DoNotOptimize(a);
    }
    state.SetItemsProcessed(state.iterations() * 64 * N);
}

template <int N>
void BM_PacketRcpSqrt(benchmark::State& state) {
    Packet<N> a = Packet<N>::ramp(1.0f, 0.5f);
    for (auto _ : state) {
        for (int i = 0; i < 16; ++i) a = rcp(sqrt(a)) + Packet<N>(1.0f);
        benchmark::DoNotOptimize(a);
    }
    state.SetItemsProcessed(state.iterations() * 16 * N);
}

template <int N>
void BM_RayBox(benchmark::State& state) {
    RayPacket<N> r;
    for (int i = 0; i < N; ++i) r.setLane(i, {0, 0, -5}, normalize(Vec3f{0.001f * float(i), 0.01f, 1.0f}));
    r.commonOrigin = true;
    r.finalize();
    const Packet<N> tFar(kInfinity);
    int hits = 0;
    for (auto _ : state) {
        for (int k = 0; k < Packet<N>::C; ++k) hits += any(chunkHitsBox<true>({-1, -1, -1}, {1, 1, 1}, r, tFar, k));
        benchmark::DoNotOptimize(hits);
    }
    state.SetItemsProcessed(state.iterations() * N);
}

const SphereScene& spheres() {
    static const SphereScene s = SphereScene::demo(10000);
    return s;
}

template <int N>
void BM_SphereTraversal(benchmark::State& state) {
    const SphereScene& s = spheres();
    constexpr int W = 512, H = 512;
    CameraFrame f;
    f.eye = {0, 40, 70};
    f.at = {0, 0, 0};
    const PinholeCamera cam(f, W, H);
    constexpr int bw = packetBlockWidth(N), bh = N / bw;
    uint64_t rays = 0;
    for (auto _ : state) {
        for (int y = 0; y < H; y += bh)
            for (int x = 0; x < W; x += bw) {
                Packet<N> px, py;
                for (int i = 0; i < N; ++i) {
                    px[i] = float(x + i % bw) + 0.5f;
                    py[i] = float(y + i / bw) + 0.5f;
                }
                RayPacket<N> r;
                cam.generate<N>(px, py, r);
                auto hit = s.intersect<N>(r, Mask<N>(true));
                benchmark::DoNotOptimize(hit);
                rays += N;
            }
    }
    state.counters["Mrays/s"] = benchmark::Counter(double(rays) / 1e6, benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_PacketFma<1>);
BENCHMARK(BM_PacketFma<4>);
BENCHMARK(BM_PacketFma<16>);
BENCHMARK(BM_PacketFma<64>);
BENCHMARK(BM_PacketRcpSqrt<1>);
BENCHMARK(BM_PacketRcpSqrt<16>);
BENCHMARK(BM_PacketRcpSqrt<64>);
BENCHMARK(BM_RayBox<1>);
BENCHMARK(BM_RayBox<16>);
BENCHMARK(BM_RayBox<256>);
BENCHMARK(BM_SphereTraversal<1>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SphereTraversal<4>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SphereTraversal<16>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SphereTraversal<64>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SphereTraversal<256>)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
