#!/usr/bin/env bash
# rtfact-bench volume --mode iso: OpenVDB's level-set ray caster is the peer (VTK's CPU ray
# caster has no isosurface blend: no X server needed, none started). On the shipped tooth CT at
# 64x64 both images must agree with RTfact's fine-step isosurface (measured: RTfact 61.8 dB,
# OpenVDB 49.4 dB; a black peer image gives ~13 dB, the wrong colour ~25 dB), the peer must hit
# about the tooth's share of the rays (763 of 4096), and an isovalue above the data is a
# one-line error, exit 1; a bad --iso value is bad usage, exit 2.
# usage: bench_iso_peer.sh RTFACT_BENCH DATASETS_DIR OUT_DIR
source "$(dirname "$0")/bench_test_lib.sh"
args=(volume "$data/volumes/tooth_103x94x161_uint8.raw" --size 64x64 --frames 1 --threads 2 --step 1 --mode iso
  --tf "$data/volumes/translucent_ramp_paraview.json")

log="$out/tooth64_iso.txt"
# No DISPLAY and no Xvfb on the PATH: the run must not need VTK.
BENCH_PATH=/nonexistent run_bench "$log" "${args[@]}" --images "$out/tooth64_iso"
grep -q "^vtk " "$log" && fail "VTK ran in --mode iso"
grep -q "no isosurface blend" "$log" || fail "no note on VTK"
grep -q "^openvdb  *2 " "$log" || fail "no 2-thread OpenVDB row"
hits="$(awk '$1 == "openvdb" && $2 == "2" { for (i = 1; i < NF; ++i) if ($(i + 1) == "rays") print $i }' "$log")"
[[ "$hits" =~ ^[0-9]+$ ]] || fail "no hit count in the OpenVDB row"
((hits >= 600 && hits <= 950)) || fail "OpenVDB hit $hits of 4096 rays (the tooth covers ~770)"
ours="$(value "$log" psnr_rtfact_db)" vdb="$(value "$log" psnr_openvdb_db)"
[ -n "$ours" ] && [ -n "$vdb" ] || fail "no psnr_rtfact_db / psnr_openvdb_db"
at_least "$ours" 50 "PSNR of RTfact's isosurface"
at_least "$vdb" 40 "PSNR of OpenVDB's isosurface"
for f in tooth64_iso_openvdb.png tooth64_iso_rtfact.png tooth64_iso_reference.png; do
  [ -s "$out/$f" ] || fail "--images did not write $f"
done

# An isovalue above every voxel: nothing to compare, said in one line naming the file.
"$bench" "${args[@]}" --iso 100000 --ref-step 0 >"$out/above.txt" 2>&1
rc=$?
[ "$rc" -eq 1 ] || fail "isovalue above the data: exit $rc, expected 1"
grep -q "^rtfact-bench: error: .*tooth_103x94x161_uint8.raw.*no isosurface at isovalue 100000" "$out/above.txt" ||
  fail "isovalue above the data: $(cat "$out/above.txt")"
[ "$(grep -c "error" "$out/above.txt")" -eq 1 ] || fail "isovalue above the data: not one error line"
# Not a number: bad usage.
"$bench" "${args[@]}" --iso abc >"$out/bad.txt" 2>&1
rc=$?
[ "$rc" -eq 2 ] || fail "--iso abc: exit $rc, expected 2"
echo "PASS: RTfact ${ours} dB, OpenVDB ${vdb} dB, ${hits} rays hit"
