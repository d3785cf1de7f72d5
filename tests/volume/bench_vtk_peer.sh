#!/usr/bin/env bash
# rtfact-bench volume's VTK peer is set up like RTfact: on the shipped tooth CT at 64x64
# with the translucent ParaView ramp, VTK's image must be non-black and agree with
# RTfact's fine-step reference (PSNR bounds below; a flipped image gives 13 dB, sRGB
# instead of linear colours 20 dB, black 14 dB). Without DISPLAY the benchmark starts its
# own Xvfb, which this also exercises (several at once: each server picks a free display).
# usage: bench_vtk_peer.sh RTFACT_BENCH DATASETS_DIR OUT_DIR
source "$(dirname "$0")/bench_test_lib.sh"

if ! command -v Xvfb >/dev/null; then
  echo "SKIP: Xvfb is not installed (apt-get install xvfb; scripts/setup.sh installs it)"
  exit 77
fi

tooth="$data/volumes/tooth_103x94x161_uint8.raw"
ramp="$data/volumes/translucent_ramp_paraview.json"
args=(volume "$tooth" --size 64x64 --frames 1 --threads 2 --step 1 --tf "$ramp")

log="$out/tooth64.txt"
run_bench "$log" "${args[@]}" --images "$out/tooth64"
vtk_db="$(value "$log" psnr_vtk_db)" cast_db="$(value "$log" psnr_vtk_cast_db)" nonblack="$(value "$log" vtk_nonblack)"
[ -n "$vtk_db" ] && [ -n "$cast_db" ] && [ -n "$nonblack" ] || fail "no psnr_vtk_db / psnr_vtk_cast_db / vtk_nonblack"
grep -q "^vtk  *2 " "$log" || fail "no 2-thread VTK timing row"
# The tooth covers about a fifth of the frame (19% in RTfact's image).
awk -v v="$nonblack" 'BEGIN { exit !(v >= 0.1 && v <= 0.4) }' || fail "VTK image non-black fraction $nonblack"
# Window read-back (after VTK's texture draw; measured 34 dB) and the mapper's own image (55 dB).
at_least "$vtk_db" 30 "PSNR of VTK's window image"
at_least "$cast_db" 45 "PSNR of VTK's cast image"
for f in tooth64_vtk.png tooth64_rtfact.png tooth64_reference.png; do
  [ -s "$out/$f" ] || fail "--images did not write $f"
done

# --mode mip: VTK's maximum intensity blend (opacity 1, as RTfact's MIP) against RTfact's
# fine-step MIP. The whole box shows (the ramp's low end is opaque brown: 45% of the frame);
# a composite blend would show the box's faces alone (~10 dB). Measured 30 dB (window) and 34
# dB (cast) at 64x64, where the box's edge pixels weigh most. OpenVDB's march is DVR only.
mlog="$out/tooth64_mip.txt"
run_bench "$mlog" "${args[@]}" --mode mip
mip_db="$(value "$mlog" psnr_vtk_db)" mip_cast_db="$(value "$mlog" psnr_vtk_cast_db)"
mip_nonblack="$(value "$mlog" vtk_nonblack)"
[ -n "$mip_db" ] && [ -n "$mip_cast_db" ] && [ -n "$mip_nonblack" ] || fail "MIP: no PSNR / non-black figures"
awk -v v="$mip_nonblack" 'BEGIN { exit !(v >= 0.35 && v <= 0.6) }' || fail "VTK MIP non-black fraction $mip_nonblack"
at_least "$mip_db" 26 "PSNR of VTK's MIP window image"
at_least "$mip_cast_db" 28 "PSNR of VTK's MIP cast image"
grep -q "^ratio  *2 " "$mlog" || fail "MIP: no 2-thread ratio row"
grep -q "^openvdb " "$mlog" && fail "MIP: OpenVDB ran"
grep -q "OpenVDB peer marches DVR only; left out in --mode mip" "$mlog" || fail "MIP: no note on OpenVDB"

# Without DISPLAY and without Xvfb: a one-line error naming the command to run, exit 1.
env -u DISPLAY PATH=/nonexistent "$bench" "${args[@]}" >"$out/noxvfb.txt" 2>&1
rc=$?
[ "$rc" -eq 1 ] || fail "no Xvfb: exit $rc, expected 1"
grep -q "error: VTK: .*xvfb-run -a rtfact-bench volume" "$out/noxvfb.txt" || fail "no Xvfb: $(cat "$out/noxvfb.txt")"
# --no-vtk needs no X server.
env -u DISPLAY PATH=/nonexistent "$bench" "${args[@]}" --no-vtk --ref-step 0 >"$out/novtk.txt" 2>&1 ||
  fail "--no-vtk without X: $(cat "$out/novtk.txt")"
grep -q "^vtk " "$out/novtk.txt" && fail "--no-vtk still ran VTK"
echo "PASS: VTK window ${vtk_db} dB, cast ${cast_db} dB, non-black ${nonblack}; MIP ${mip_db} / ${mip_cast_db} dB"
