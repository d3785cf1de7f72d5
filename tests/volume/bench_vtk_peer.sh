#!/usr/bin/env bash
# rtfact-bench volume's VTK peer is set up like RTfact: on the shipped tooth CT at 64x64
# with the translucent ParaView ramp, VTK's image must be non-black and agree with
# RTfact's fine-step reference (PSNR bounds below; a flipped image gives 13 dB, sRGB
# instead of linear colours 20 dB, black 14 dB). Without DISPLAY the benchmark starts its
# own Xvfb, which this also exercises (several at once: each server picks a free display).
# usage: bench_vtk_peer.sh RTFACT_BENCH DATASETS_DIR OUT_DIR
set -uo pipefail
bench="$1" data="$2" out="$3"
mkdir -p "$out"
fail() {
  echo "FAIL: $*"
  exit 1
}

if ! command -v Xvfb >/dev/null; then
  echo "SKIP: Xvfb is not installed (apt-get install xvfb; scripts/setup.sh installs it)"
  exit 77
fi

tooth="$data/volumes/tooth_103x94x161_uint8.raw"
ramp="$data/volumes/translucent_ramp_paraview.json"
args=(volume "$tooth" --size 64x64 --frames 1 --threads 2 --step 1 --tf "$ramp")

log="$out/tooth64.txt"
env -u DISPLAY "$bench" "${args[@]}" --images "$out/tooth64" >"$log" 2>&1
rc=$?
[ "$rc" -eq 0 ] || {
  cat "$log"
  fail "rtfact-bench volume exited with $rc"
}
cat "$log"
value() { grep -o "$1=[0-9.]*" "$log" | head -1 | cut -d= -f2; }
vtk_db="$(value psnr_vtk_db)" cast_db="$(value psnr_vtk_cast_db)" nonblack="$(value vtk_nonblack)"
[ -n "$vtk_db" ] && [ -n "$cast_db" ] && [ -n "$nonblack" ] || fail "no psnr_vtk_db / psnr_vtk_cast_db / vtk_nonblack"
grep -q "^vtk  *2 " "$log" || fail "no 2-thread VTK timing row"
# The tooth covers about a fifth of the frame (19% in RTfact's image).
awk -v v="$nonblack" 'BEGIN { exit !(v >= 0.1 && v <= 0.4) }' || fail "VTK image non-black fraction $nonblack"
# Window read-back (after VTK's texture draw; measured 34 dB) and the mapper's own image (55 dB).
awk -v v="$vtk_db" 'BEGIN { exit !(v >= 30) }' || fail "PSNR of VTK's window image $vtk_db dB < 30"
awk -v v="$cast_db" 'BEGIN { exit !(v >= 45) }' || fail "PSNR of VTK's cast image $cast_db dB < 45"
for f in tooth64_vtk.png tooth64_rtfact.png tooth64_reference.png; do
  [ -s "$out/$f" ] || fail "--images did not write $f"
done

# Without DISPLAY and without Xvfb: a one-line error naming the command to run, exit 1.
env -u DISPLAY PATH=/nonexistent "$bench" "${args[@]}" >"$out/noxvfb.txt" 2>&1
rc=$?
[ "$rc" -eq 1 ] || fail "no Xvfb: exit $rc, expected 1"
grep -q "error: VTK: .*xvfb-run -a rtfact-bench volume" "$out/noxvfb.txt" || fail "no Xvfb: $(cat "$out/noxvfb.txt")"
# --no-vtk needs no X server.
env -u DISPLAY PATH=/nonexistent "$bench" "${args[@]}" --no-vtk --ref-step 0 >"$out/novtk.txt" 2>&1 ||
  fail "--no-vtk without X: $(cat "$out/novtk.txt")"
grep -q "^vtk " "$out/novtk.txt" && fail "--no-vtk still ran VTK"
echo "PASS: VTK window ${vtk_db} dB, cast ${cast_db} dB, non-black ${nonblack}"
