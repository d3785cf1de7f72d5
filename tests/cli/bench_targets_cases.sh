#!/usr/bin/env bash
# scripts/bench-targets: the verdict on each performance target from a real bench-figures
# run (tests/data/bench_figures_zen5_avx2.txt: Zen 5, the -DRTFACT_ISA=avx2 build, with its
# own summary at the end, as --out writes it), a run with sections missing, and bad input.
# usage: bench_targets_cases.sh SOURCE_DIR WORK_DIR
set -u
src="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
targets="$src/scripts/bench-targets"
fails=0 passes=0
check() {  # check DESCRIPTION COMMAND...: the command must succeed
  local what="$1"
  shift
  if "$@"; then passes=$((passes + 1)); else echo "FAIL: $what"; fails=$((fails + 1)); fi
}

# A full run: every target has its figure, verdicts and figures as that run measured them.
"$targets" "$src/tests/data/bench_figures_zen5_avx2.txt" >full.txt 2>err.txt
check "full run exits 0" test $? -eq 0
check "full run: nothing on stderr" test ! -s err.txt
has() { grep -Eq -- "$1" "$2"; }
check "header names the run" has '^== targets of issues 16 and 17 in this run: AMD EPYC, AVX-512 CPU, build ISA avx2,' full.txt
check "primary rays met" has '^met +16: primary rays >= 1.0x Embree, wide BVH, dragon 100k \(1T / 2T\) 1.14 / 1.11$' full.txt
check "AO missed" has '^missed +16: AO rays >= 1.0x Embree rtcOccluded1, dragon 100k \(1T / 2T\) 0.972 / 0.956$' full.txt
check "build time ratio" has '^met +16: BVH build time <= 1.0x Embree medium, 2T, 2.5M grid \(ratio\) 0.722$' full.txt
check "speed-up from the two rows" has '^met +16: 2 threads >= 1.8x 1 thread, primary rays, dragon 100k \(1T CPU time, 2T wall time\) \(speed-up\) 1.81$' full.txt
check "points full detail, worse of 1T / 2T" has '^missed +16: points full detail >= 3x Embree.s discs, 2M dragon \(1T / 2T\) 2.92 / 2.83$' full.txt
check "LoD: best quality at >= 30 dB" has '^missed +16: LoD >= 10x Embree at >= 30 dB, 32M dragon, 2T \(best ratio at 35.6 dB, object 26.1 dB\) 8.69$' full.txt
check "LoD build rate" has '^missed +16: LoD build >= 10M points/s, 2T, 32M dragon \(first build\) \(M points/s\) 7.23$' full.txt
check "VTK ratio" has '^met +17: >= 5x VTK FixedPoint, head CT \(1T / 2T\) 6.32 / 6.52$' full.txt
check "PSNR over VTK" has '^met +17: PSNR >= VTK.s against the fine-step reference, bonsai CT \(dB over VTK\) 11.8$' full.txt
check "phantom table row" has '^met +17: 512\^3 u16 translucent phantom <= 150 ms, 2T \(ms\) 113$' full.txt
check "every-step rate" has '^missed +17: >= 300 Msamples/s per core, 512\^3 phantom, every step \(Msamples/s\) 209$' full.txt
check "counts" has '^== 31 met, 6 missed, 12 not in this run$' full.txt
check "no shaded runs then: n/a" has '^n/a +17: shaded DVR >= 5x VTK FixedPoint shaded, tooth CT \(1T / 2T\) - / -$' full.txt
check "no MIP runs then: n/a" has '^n/a +17: MIP >= 5x VTK FixedPoint MIP, bonsai CT \(1T / 2T\) - / -$' full.txt

# Sections not run (bench-figures --only volume): their targets are n/a, not missed; wall
# clock (no --cpu-clock): no clock note. A LoD quality under 30 dB does not count.
{
  echo "== rtfact-bench figures: Test CPU, AVX2 CPU, build ISA native, 2 cores, load 0 0 0, 2026-01-01 00:00 UTC, commit 0000000"
  echo "-- points: dragon 32000000 points, wide BVH (median split)"
  echo "   build_ms: rtfact=2000.0 embree=6000.0 ratio_build_time=0.333 rtfact_points_per_s=1.6e+07"
  echo "   threads=1 frame_ms: full=100.0 lod=40.0 embree=250.0"
  echo "   threads=2 frame_ms: full=50.0 lod=20.0 embree=130.0"
  echo "   threads=2 mrays: full=20.0 lod=50.0 embree=8.0 ratio_full=2.6 ratio_lod=6.5"
  echo "   psnr_lod_vs_full=36.0 object_psnr=27.0"
  echo "   quality=8 rep_scale=0.7 threads=2 lod_frame_ms=12.0 embree_frame_ms=130.0 ratio_lod=10.8 psnr_lod_vs_full=31.0"
  echo "   quality=16 rep_scale=0.7 threads=2 lod_frame_ms=9.0 embree_frame_ms=130.0 ratio_lod=14.4 psnr_lod_vs_full=29.9"
} >partial.figures
"$targets" partial.figures >partial.txt 2>&1
check "partial run exits 0" test $? -eq 0
check "absent section is n/a" has '^n/a +16: primary rays >= 1.0x Embree, wide BVH, dragon 100k \(1T / 2T\) - / -$' partial.txt
check "LoD under 30 dB left out" has '^met +16: LoD >= 10x Embree at >= 30 dB, 32M dragon, 2T \(best ratio at 31.0 dB\) 10.8$' partial.txt
check "build rate from points/s" has '^met +16: LoD build >= 10M points/s, 2T, 32M dragon \(first build\) \(M points/s\) 16$' partial.txt
check "wall clock: no clock note" has '^met +16: 2 threads >= 1.8x 1 thread, points full detail, 32M dragon \(speed-up\) 2$' partial.txt
check "partial counts" has '^== 3 met, 0 missed, 46 not in this run$' partial.txt

# No LoD quality reaches 30 dB: missed, and said so.
{
  echo "== rtfact-bench figures: Test CPU, AVX2 CPU, build ISA native, 2 cores, load 0 0 0, 2026-01-01 00:00 UTC, commit 0000000"
  echo "-- points: dragon 32000000 points, wide BVH (median split)"
  echo "   quality=24 rep_scale=0.7 threads=2 lod_frame_ms=6.0 embree_frame_ms=130.0 ratio_lod=21.7 psnr_lod_vs_full=25.0 object_psnr=19.0"
} >coarse.figures
"$targets" coarse.figures >coarse.txt 2>&1
check "coarse LoD only: missed" has '^missed +16: LoD >= 10x Embree at >= 30 dB, 32M dragon, 2T \(no quality at >= 30 dB\) 0$' coarse.txt

# Two builds (rtfact-bench since session 37): the first is judged, the best shown beside it.
{
  echo "== rtfact-bench figures: Test CPU, AVX2 CPU, build ISA native, 2 cores, load 0 0 0, 2026-01-01 00:00 UTC, commit 0000000"
  echo "-- points: dragon 32000000 points, wide BVH (median split)"
  echo "   build_ms: rtfact=3100.0 embree=6000.0 ratio_build_time=0.517 rtfact_points_per_s=1.03e+07"
  echo "   build_first_ms: rtfact=3950.0 embree=7000.0 ratio_build_time=0.564 rtfact_points_per_s=8.1e+06 (the first of 2 builds, fresh memory)"
} >builds.figures
"$targets" builds.figures >builds.txt 2>&1
check "first build judged, best shown" has '^missed +16: LoD build >= 10M points/s, 2T, 32M dragon \(first build; best of two 10.3\) \(M points/s\) 8.1$' builds.txt

# The every-step rate from rtfact-bench volume's table (since session 39: best of frames).
{
  echo "== rtfact-bench figures: Test CPU, AVX2 CPU, build ISA native, 2 cores, load 0 0 0, 2026-01-01 00:00 UTC, commit 0000000"
  echo "-- volume: 512^3 u16 translucent phantom, every step, one thread"
  echo "   rtfact         1      201.3      5.21       315.4     63484615"
} >every.figures
"$targets" every.figures >every.txt 2>&1
check "every-step rate from the table" has '^met +17: >= 300 Msamples/s per core, 512\^3 phantom, every step \(Msamples/s\) 315$' every.txt

# Shaded DVR against VTK's shading (since session 44), both thread counts judged.
{
  echo "== rtfact-bench figures: Test CPU, AVX2 CPU, build ISA native, 2 cores, load 0 0 0, 2026-01-01 00:00 UTC, commit 0000000"
  echo "-- volume: quarter.nhdr shaded vs VTK"
  echo "   threads=1 rtfact_ms=41.3 vtk_ms=215.0 vtk/rtfact=5.21x"
  echo "   threads=2 rtfact_ms=23.0 vtk_ms=113.4 vtk/rtfact=4.93x"
} >shaded.figures
"$targets" shaded.figures >shaded.txt 2>&1
check "shaded: the worse thread count misses" has '^missed +17: shaded DVR >= 5x VTK FixedPoint shaded, head CT \(1T / 2T\) 5.21 / 4.93$' shaded.txt
check "shaded: not the unshaded target" has '^n/a +17: >= 5x VTK FixedPoint, head CT \(1T / 2T\) - / -$' shaded.txt

# MIP against VTK's maximum intensity blend (since session 45), both thread counts judged.
{
  echo "== rtfact-bench figures: Test CPU, AVX2 CPU, build ISA native, 2 cores, load 0 0 0, 2026-01-01 00:00 UTC, commit 0000000"
  echo "-- volume: tooth_103x94x161_uint8.mhd MIP vs VTK"
  echo "   threads=1 rtfact_ms=102.8 vtk_ms=645.0 vtk/rtfact=6.27x"
  echo "   threads=2 rtfact_ms=72.2 vtk_ms=443.7 vtk/rtfact=6.14x"
  echo "-- volume: bonsai_ct.nii.gz MIP vs VTK"
  echo "   threads=1 rtfact_ms=136.8 vtk_ms=744.4 vtk/rtfact=5.44x"
  echo "   threads=2 rtfact_ms=150.0 vtk_ms=692.2 vtk/rtfact=4.61x"
} >mip.figures
"$targets" mip.figures >mip.txt 2>&1
check "MIP: met at both thread counts" has '^met +17: MIP >= 5x VTK FixedPoint MIP, tooth CT \(1T / 2T\) 6.27 / 6.14$' mip.txt
check "MIP: the worse thread count misses" has '^missed +17: MIP >= 5x VTK FixedPoint MIP, bonsai CT \(1T / 2T\) 5.44 / 4.61$' mip.txt
check "MIP: not the shaded target" has '^n/a +17: shaded DVR >= 5x VTK FixedPoint shaded, tooth CT \(1T / 2T\) - / -$' mip.txt

# Isosurfaces against OpenVDB's level-set ray caster (since session 45): speed at both thread
# counts, and PSNR against the fine-step reference over OpenVDB's.
{
  echo "== rtfact-bench figures: Test CPU, AVX2 CPU, build ISA native, 2 cores, load 0 0 0, 2026-01-01 00:00 UTC, commit 0000000"
  echo "-- volume: bonsai_ct.nii.gz isosurface vs OpenVDB level set"
  echo "   threads=1 rtfact_ms=59.5 openvdb_ms=381.5 openvdb/rtfact=6.41x"
  echo "   threads=2 rtfact_ms=29.3 openvdb_ms=201.8 openvdb/rtfact=6.88x"
  echo "   psnr_rtfact_db=49.94 [41.47] psnr_openvdb_db=40.51 [33.36]"
  echo "-- volume: quarter.nhdr isosurface vs OpenVDB level set"
  echo "   threads=1 rtfact_ms=46.6 openvdb_ms=220.8 openvdb/rtfact=4.74x"
  echo "   threads=2 rtfact_ms=23.7 openvdb_ms=203.4 openvdb/rtfact=8.57x"
  echo "   psnr_rtfact_db=34.00 [33.98] psnr_openvdb_db=34.91 [29.12]"
} >iso.figures
"$targets" iso.figures >iso.txt 2>&1
check "iso: met at both thread counts" has "^met +17: isosurface >= 5x OpenVDB's level-set ray caster, bonsai CT \(1T / 2T\) 6.41 / 6.88$" iso.txt
check "iso: PSNR over OpenVDB" has "^met +17: isosurface PSNR >= OpenVDB's against the fine-step reference, bonsai CT \(dB over OpenVDB\) 9.43$" iso.txt
check "iso: the worse thread count misses" has "^missed +17: isosurface >= 5x OpenVDB's level-set ray caster, head CT \(1T / 2T\) 4.74 / 8.57$" iso.txt
check "iso: a worse PSNR misses" has "^missed +17: isosurface PSNR >= OpenVDB's against the fine-step reference, head CT \(dB over OpenVDB\) -0.91$" iso.txt
check "iso: not the DVR OpenVDB target" has '^n/a +17: >= 10x OpenVDB, bonsai CT \(1T / 2T\) - / -$' iso.txt

# Bad input: one line naming the file and the problem, exit 1; bad usage exit 2.
"$targets" "$work/missing.txt" >out.txt 2>err.txt
check "missing file: exit 1" test $? -eq 1
check "missing file: message" has "^bench-targets: $work/missing.txt: no such file or directory$" err.txt
check "missing file: no stdout" test ! -s out.txt
printf 'threads=1 rtfact_ms=1\n' >not-figures.txt
"$targets" not-figures.txt >out.txt 2>err.txt
check "not figures: exit 1" test $? -eq 1
check "not figures: message" has "^bench-targets: not-figures.txt: not bench-figures output \(no '== rtfact-bench figures' header\)$" err.txt
check "not figures: one line" test "$(wc -l <err.txt)" -eq 1
"$targets" >out.txt 2>err.txt
check "no file: exit 2" test $? -eq 2
"$targets" a b >out.txt 2>err.txt
check "two files: exit 2" test $? -eq 2

echo "bench-targets cases: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
