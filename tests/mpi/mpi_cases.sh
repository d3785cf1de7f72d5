#!/usr/bin/env bash
# rtfact under mpirun (tests/mpi/CMakeLists.txt sets the OpenMPI environment).
# usage: mpi_cases.sh identical|failing SCENE RTFACT MPIEXEC DATASETS WORK_DIR
#   identical: the image of 2, 3 and 4 ranks (--distribute image) equals the
#              single-process image bit for bit (float EXR pixels; the files differ in
#              their DateTime), and -np 1 too.
#   failing:   a rank given a file it cannot read (MPMD launch: the other ranks get the
#              real file) makes every rank exit non-zero with one error line naming the
#              rank, within the timeout, and no image is written; --distribute data is a
#              usage error (exit 2).
set -u
what="$1" scene="$2" rtfact="$3" mpiexec="$4" data="$5" work="$6"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
launch=("$mpiexec" --oversubscribe --allow-run-as-root)
fails=0
fail() {
  echo "FAIL: $*"
  fails=$((fails + 1))
}

# Small, uneven sizes (partial tiles), two samples per pixel (accumulation order).
common=(--size 150x97 --spp 2 --threads 1 --quiet)
case "$scene" in
  # EDL (on by default for this scan) is not applied under mpirun yet (docs/mpi.md).
  points) args=(points "$data/points/bunny_bun000.ply" --edl 0) ;;
  volume) args=(volume "$data/volumes/tooth_103x94x161_uint8.mhd") ;;
  mesh) args=(mesh "$data/meshes/bunny.ply") ;;
  spheres) args=(spheres) ;;
esac

# Every float of every pixel equal (idiff exits 0 only when no value differs at all).
same() { idiff -fail 0 -failpercent 0 -warn 0 single.exr "$1" >/dev/null; }

if [ "$what" = identical ]; then
  timeout 300 "$rtfact" "${args[@]}" "${common[@]}" -o single.exr || fail "single-process render"
  for np in 1 2 3 4; do
    out="np$np.exr"
    timeout 300 "${launch[@]}" -np "$np" "$rtfact" "${args[@]}" "${common[@]}" --distribute image --stats \
      -o "$out" >"np$np.stats" 2>"np$np.err" || {
      fail "-np $np exited $?: $(cat "np$np.err")"
      continue
    }
    same "$out" || fail "-np $np: image differs from the single-process image"
    if [ "$np" -gt 1 ]; then
      grep -q "^mpi_ranks=$np$" "np$np.stats" || fail "-np $np: no mpi_ranks=$np in --stats"
      # Every tile is rendered once: the ranks' tiles add up to the image's 5x4 tiles.
      tiles=$(grep -E '^rank[0-9]+_tiles=' "np$np.stats" | cut -d= -f2 | paste -sd+ | bc)
      [ "$tiles" = 20 ] || fail "-np $np: ranks rendered $tiles tiles, want 20"
      [ "$(grep -cE '^rank[0-9]+_bytes=[1-9]' "np$np.stats")" = "$np" ] || fail "-np $np: bytes moved missing"
    fi
  done
  # The single-process image is not empty (a broken comparison cannot pass silently).
  [ "$(stat -c %s single.exr)" -gt 1000 ] || fail "single-process image suspiciously small"
else
  for bad in 0 2; do
    # Rank `bad` is started with a file that does not exist on its "node".
    ranks=()
    for r in 0 1 2; do
      [ ${#ranks[@]} -gt 0 ] && ranks+=(:)
      file="$data/points/bunny_bun000.ply"
      [ "$r" = "$bad" ] && file="$work/missing_on_rank_$r.ply"
      ranks+=(-np 1 "$rtfact" points "$file" "${common[@]}" -o "bad$bad.png")
    done
    timeout 120 "${launch[@]}" "${ranks[@]}" >"bad$bad.out" 2>"bad$bad.err"
    rc=$?
    [ "$rc" = 124 ] && fail "rank $bad failing: mpirun hung (timeout)"
    [ "$rc" = 0 ] && fail "rank $bad failing: mpirun exited 0"
    lines=$(grep -c "^rtfact: error:" "bad$bad.err")
    [ "$lines" = 1 ] || fail "rank $bad failing: $lines error lines, want 1: $(cat "bad$bad.err")"
    grep -q "^rtfact: error: rank $bad: .*missing_on_rank_$bad.ply" "bad$bad.err" ||
      fail "rank $bad failing: the error line does not name rank $bad and its file: $(cat "bad$bad.err")"
    [ -e "bad$bad.png" ] && fail "rank $bad failing: an image was written"
  done
  timeout 120 "${launch[@]}" -np 2 "$rtfact" "${args[@]}" "${common[@]}" --distribute data -o data.png \
    >/dev/null 2>data.err
  rc=$?
  [ "$rc" = 2 ] || fail "--distribute data: exit $rc, want 2"
  grep -q "not supported yet" data.err || fail "--distribute data: no 'not supported yet' in: $(cat data.err)"
fi
[ "$fails" = 0 ] && echo "mpi $what $scene: ok"
exit $((fails > 0))
