#!/usr/bin/env bash
# rtfact under mpirun (tests/mpi/CMakeLists.txt sets the OpenMPI environment).
# usage: mpi_cases.sh identical|failing|data|data_failing|view SCENE RTFACT MPIEXEC DATASETS WORK_DIR [COMPARE]
#   identical: the image of 2, 3 and 4 ranks (--distribute image) equals the
#              single-process image bit for bit (float EXR pixels; the files differ in
#              their DateTime), and -np 1 too.
#   failing:   a rank given a file it cannot read (MPMD launch: the other ranks get the
#              real file) makes every rank exit non-zero with one error line naming the
#              rank, within the timeout, and no image is written; --distribute data is a
#              usage error (exit 2) for anything but volumes.
#   data:      --distribute data (volumes): 2, 3 and 4 ranks within the regression
#              tolerance of one process (COMPARE: tests/common/image_compare.h's metric),
#              with features straddling the slab borders (phantom), no seam in a
#              homogeneous slab crossing them (every channel within 2/255), and each rank
#              loading about 1/N of the volume plus ghosts (bytes read and VmHWM).
#   data_failing: a volume file cut short so that only the last rank's slab is missing:
#              every rank exits 1, one error line naming that rank (points: a rank
#              without its file).
#   data points: data-parallel clouds within the regression tolerance of one process.
#   view:      `mpirun -np 2 rtfact view` streams the single-process viewer's frames
#              (COMPARE: the scripted client, tests/mpi/mpi_view_client.cpp).
set -u
what="$1" scene="$2" rtfact="$3" mpiexec="$4" data="$5" work="$6" compare="${7:-}"
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
  # EDL is on by default for this scan: rank 0 applies it to the gathered depth.
  points) args=(points "$data/points/bunny_bun000.ply") ;;
  volume) args=(volume "$data/volumes/tooth_103x94x161_uint8.mhd") ;;
  mesh) args=(mesh "$data/meshes/bunny.ply") ;;
  spheres) args=(spheres) ;;
esac

# Every float of every pixel equal (idiff exits 0 only when no value differs at all).
same() { idiff -fail 0 -failpercent 0 -warn 0 single.exr "$1" >/dev/null; }

# --stats value of KEY in FILE.
stat_of() { grep "^$2=" "$1" | head -1 | cut -d= -f2; }

if [ "$what" = view ]; then
  # The viewer served by rank 0 of `mpirun -np 2` streams the same frames as a
  # single-process viewer (lossless PNG, every sample accumulated): the home view, after a
  # drag, after a settings change; EDL on (the scan has no normals). Stopping rank 0 ends
  # every rank cleanly (mpirun exits 0).
  client="$compare"
  vargs=(view points "$data/points/bunny_bun000.ply" --no-browser --port 0 --size 100x70 --max-samples 3
    --threads 1 --quiet)
  # Starts a server (its pid in $server); waits for its URL; runs the client.
  drive() {
    local name=$1
    shift
    "$@" "${vargs[@]}" >"$name.out" 2>"$name.err" &
    server=$!
    local url=""
    for ((i = 0; i < 600; i++)); do
      url=$(grep -o 'http://[^ ]*' "$name.out" 2>/dev/null | head -1)
      [ -n "$url" ] && break
      kill -0 "$server" 2>/dev/null || break
      sleep 0.2
    done
    [ -n "$url" ] || {
      fail "$name: no URL from the viewer: $(cat "$name.err")"
      return 1
    }
    local port token
    port=$(echo "$url" | sed -E 's|http://[^:]+:([0-9]+)/.*|\1|')
    token=$(echo "$url" | sed -E 's|.*token=([^&]+).*|\1|')
    timeout 300 "$client" "$port" "$token" "$name" >"$name.client" 2>&1 || fail "$name: client: $(cat "$name.client")"
  }
  drive single "$rtfact"
  kill -TERM "$server"
  wait "$server" || fail "single-process viewer exited $?"
  drive mpi "${launch[@]}" -np 2 "$rtfact"
  # Only rank 0 serves (a rank serving alone would pass the comparison too).
  [ "$(grep -c 'viewing at' mpi.out)" = 1 ] || fail "not one server under mpirun: $(cat mpi.out)"
  # Stop rank 0 (the server): it tells rank 1, and both exit.
  rank0=""
  for child in $(pgrep -P "$server"); do
    tr '\0' '\n' <"/proc/$child/environ" 2>/dev/null | grep -qx OMPI_COMM_WORLD_RANK=0 && rank0=$child
  done
  if [ -n "$rank0" ]; then
    kill -TERM "$rank0"
  else
    fail "no rank 0 process under mpirun $server"
    kill -TERM "$server"
  fi
  for ((i = 0; i < 600; i++)); do
    kill -0 "$server" 2>/dev/null || break
    sleep 0.2
  done
  if kill -0 "$server" 2>/dev/null; then
    fail "mpirun still running 120 s after rank 0 stopped (a rank hung)"
    kill -KILL "$server"
  fi
  wait "$server"
  rc=$?
  [ "$rc" = 0 ] || fail "mpirun exited $rc after the viewer stopped: $(cat mpi.err)"
  grep -q "2 ranks serve the viewer" mpi.err && fail "--quiet: rank 0 still announced the ranks"
  for v in home moved normal; do
    [ -s "single-$v.png" ] && [ -s "mpi-$v.png" ] || {
      fail "$v: frame missing"
      continue
    }
    idiff -fail 0 -failpercent 0 -warn 0 "single-$v.png" "mpi-$v.png" >/dev/null ||
      fail "$v: the mpirun viewer's frame differs from one process's: $(idiff "single-$v.png" "mpi-$v.png" | grep -i max)"
  done
  # The views differ from each other (the comparison can fail).
  idiff -fail 0 -failpercent 0 -warn 0 single-home.png single-normal.png >/dev/null && fail "home equals normal"
elif [ "$what" = data ] && [ "$scene" = points ]; then
  # Data-parallel clouds: the bunny scan (no normals: normals and radii estimated, so the
  # ghost points matter; EDL on by default) and with EDL off, against one process.
  cloud="$data/points/bunny_bun000.ply"
  pcommon=(--size 200x150 --spp 2 --threads 1 --quiet)
  n=$(grep -a -m1 "^element vertex" "$cloud" | cut -d' ' -f3)
  for edl in default 0; do
    extra=()
    [ "$edl" = 0 ] && extra=(--edl 0)
    timeout 300 "$rtfact" points "$cloud" "${extra[@]}" "${pcommon[@]}" -o "single-$edl.exr" ||
      fail "edl $edl: single-process render"
    for np in 1 2 3 4; do
      out="edl-$edl-np$np.exr"
      timeout 300 "${launch[@]}" -np "$np" "$rtfact" points "$cloud" "${extra[@]}" "${pcommon[@]}" \
        --distribute data --stats -o "$out" >"$out.stats" 2>"$out.err" || {
        fail "edl $edl -np $np exited $?: $(cat "$out.err")"
        continue
      }
      cmp=$("$compare" "single-$edl.exr" "$out") || fail "edl $edl -np $np: $cmp"
      echo "edl $edl -np $np: $cmp"
      [ "$np" = 1 ] && continue # one process: MPI is not started
      [ "$(stat_of "$out.stats" mpi_distribute)" = data ] || fail "edl $edl -np $np: not data-parallel"
      # Every point is owned by exactly one rank, each about 1/N of them (quantile cells).
      total=0
      for ((r = 0; r < np; r++)); do
        own=$(stat_of "$out.stats" "rank${r}_points")
        [ -n "$own" ] && [ $((own * np * 100)) -ge $((n * 98)) ] && [ $((own * np * 100)) -le $((n * 102)) ] ||
          fail "edl $edl -np $np: rank $r holds '$own' of $n points, not about 1/$np"
        total=$((total + ${own:-0}))
        [ "$(stat_of "$out.stats" "rank${r}_bytes")" -gt 0 ] || fail "edl $edl -np $np: rank $r moved no bytes"
      done
      [ "$total" = "$n" ] || fail "edl $edl -np $np: ranks hold $total points, the cloud $n"
    done
  done
  # The parts differ from one process (the check can fail): the cells rendered alone.
  timeout 300 "$rtfact" points "$cloud" --edl 0 --crop -1,-1,-0.02,1 "${pcommon[@]}" -o half.exr || fail "half render"
  "$compare" single-0.exr half.exr >/dev/null && fail "half of the cloud passes the comparison"
  [ "$(stat -c %s single-0.exr)" -gt 1000 ] || fail "single-process image suspiciously small"
elif [ "$what" = data_failing ] && [ "$scene" = points ]; then
  # Rank 1 of 3 cannot read its file: every rank exits 1, one line naming rank 1.
  ranks=()
  for r in 0 1 2; do
    [ ${#ranks[@]} -gt 0 ] && ranks+=(:)
    file="$data/points/bunny_bun000.ply"
    [ "$r" = 1 ] && file="$work/missing_on_rank_1.ply"
    ranks+=(-np 1 "$rtfact" points "$file" "${common[@]}" --distribute data -o bad.png)
  done
  timeout 120 "${launch[@]}" "${ranks[@]}" >bad.out 2>bad.err
  rc=$?
  [ "$rc" = 124 ] && fail "data-parallel cloud: mpirun hung (timeout)"
  [ "$rc" = 1 ] || fail "data-parallel cloud: mpirun exited $rc, want 1"
  lines=$(grep -c "^rtfact: error:" bad.err)
  [ "$lines" = 1 ] || fail "data-parallel cloud: $lines error lines, want 1: $(cat bad.err)"
  grep -q "^rtfact: error: rank 1: .*missing_on_rank_1.ply" bad.err ||
    fail "data-parallel cloud: the line does not name rank 1 and its file: $(cat bad.err)"
  [ -e bad.png ] && fail "data-parallel cloud: an image was written"
  # A non-eyelight integrator needs the whole cloud: a usage error.
  timeout 120 "${launch[@]}" -np 2 "$rtfact" points "$data/points/bunny_bun000.ply" "${common[@]}" \
    --distribute data --integrator ao -o ao.png >/dev/null 2>ao.err
  rc=$?
  [ "$rc" = 2 ] || fail "--integrator ao data-parallel: exit $rc, want 2: $(cat ao.err)"
elif [ "$what" = data ]; then
  "$rtfact" gen volume phantom --size 64 --quiet -o phantom.mhd || fail "gen phantom"
  "$rtfact" gen volume slab --size 64 --thickness 40 --quiet -o slab.mhd || fail "gen slab"
  vcommon=(--size 160x120 --threads 1 --quiet)
  # The seam test's TF: translucent (3% opacity per voxel at 255), so no ray terminates
  # early and one sample too many or too few at a slab border (1.5% alpha) would show.
  echo '{"name":"seam","space":"data","colors":[[0,1,1,1],[255,1,1,1]],"opacity":[[0,0],[128,0],[255,0.03]]}' \
    >seam.json
  for vol in phantom:dvr phantom:shaded slab:dvr; do
    name=${vol%%:*} mode=${vol##*:}
    extra=()
    [ "$name" = slab ] && extra=(--tf seam.json)
    timeout 300 "$rtfact" volume "$name.mhd" --mode "$mode" "${extra[@]}" "${vcommon[@]}" -o "$name-$mode.exr" ||
      fail "$name $mode: single-process render"
    for np in 2 3 4; do
      [ "$mode" = shaded ] && [ "$np" != 3 ] && continue # the ghost slices' gradients: one run
      out="$name-$mode-np$np.exr"
      timeout 300 "${launch[@]}" -np "$np" "$rtfact" volume "$name.mhd" --mode "$mode" "${extra[@]}" "${vcommon[@]}" \
        --distribute data --stats -o "$out" >"$out.stats" 2>"$out.err" || {
        fail "$name $mode -np $np exited $?: $(cat "$out.err")"
        continue
      }
      cmp=$("$compare" "$name-$mode.exr" "$out") || fail "$name $mode -np $np: $cmp"
      echo "$name $mode -np $np: $cmp"
      # No seam: every float within 1e-4 of one process (re-associated rounding only).
      if [ "$name" = slab ]; then
        idiff -fail 1e-4 -failpercent 0 "$name-$mode.exr" "$out" >/dev/null ||
          fail "slab -np $np: differs by more than 1e-4 (a seam at a slab border?): $(idiff "$name-$mode.exr" "$out" | grep Max)"
      fi
      [ "$(stat_of "$out.stats" mpi_distribute)" = data ] || fail "$name -np $np: not data-parallel"
      # Each rank read its slab plus ghosts: at most ceil(63 cells / N) + 1 planes + 2 x 2
      # ghost slices of 64 x 64 x 2 bytes, and together about the volume once.
      bound=$(((63 + np - 1) / np + 1 + 4))
      total=0
      for ((r = 0; r < np; r++)); do
        bytes=$(stat_of "$out.stats" "rank${r}_loaded_bytes")
        [ -n "$bytes" ] && [ "$bytes" -gt 0 ] && [ "$bytes" -le $((bound * 8192)) ] ||
          fail "$name -np $np: rank $r loaded '$bytes' bytes, more than $bound slices"
        total=$((total + ${bytes:-0}))
        [ "$(stat_of "$out.stats" "rank${r}_bytes")" -gt 0 ] || fail "$name -np $np: rank $r moved no bytes"
      done
      [ "$total" -le $(((64 + np * 6) * 8192)) ] || fail "$name -np $np: ranks loaded $total bytes together"
    done
  done
  # Pre-integration: each segment composited by one rank (a rank's first sample taken even
  # in an empty cube, long steps ending before the slab's end) and a rank's look-back a step
  # into its neighbour's ghosts (step 4: 5 ghost slices), under a view along z: no seam.
  steep=(--eye 38,36,140 --at 31.5,31.5,31.5 --up 0,1,0)
  for vol in slab:1 slab:4 phantom:1 phantom:4; do
    name=${vol%%:*} step=${vol##*:}
    pre=(--tf seam.json --preintegrated --step "$step" "${steep[@]}")
    timeout 300 "$rtfact" volume "$name.mhd" "${pre[@]}" "${vcommon[@]}" -o "pre-$name-$step.exr" ||
      fail "pre-integrated $name step $step: single-process render"
    for np in 2 3; do
      out="pre-$name-$step-np$np.exr"
      timeout 300 "${launch[@]}" -np "$np" "$rtfact" volume "$name.mhd" "${pre[@]}" "${vcommon[@]}" --distribute data \
        --stats -o "$out" >"$out.stats" 2>"$out.err" || {
        fail "pre-integrated $name step $step -np $np exited $?: $(cat "$out.err")"
        continue
      }
      idiff -fail 1e-4 -failpercent 0 "pre-$name-$step.exr" "$out" >/dev/null ||
        fail "pre-integrated $name step $step -np $np: differs by more than 1e-4 (a seam?): $(idiff "pre-$name-$step.exr" "$out" | grep Max)"
      ghosts=$((step > 1 ? step + 1 : 2))
      [ "$(stat_of "$out.stats" mpi_ghost_slices)" = "$ghosts" ] ||
        fail "pre-integrated step $step: $(stat_of "$out.stats" mpi_ghost_slices) ghost slices, want $ghosts"
    done
  done
  # NRRD over the same voxels, raw (one seek per slab) and gzip (decompressed up to the
  # slab): the same image as the MetaImage on one process.
  gzip -kf phantom.raw
  for enc in raw:phantom.raw gzip:phantom.raw.gz; do
    printf 'NRRD0004\ntype: unsigned short\ndimension: 3\nsizes: 64 64 64\nendian: little\nencoding: %s\ndata file: %s\n' \
      "${enc%%:*}" "${enc##*:}" >"phantom-${enc%%:*}.nhdr"
    out="nrrd-${enc%%:*}.exr"
    timeout 300 "${launch[@]}" -np 3 "$rtfact" volume "phantom-${enc%%:*}.nhdr" "${vcommon[@]}" --distribute data \
      -o "$out" 2>"$out.err" || fail "nrrd ${enc%%:*} -np 3: $(cat "$out.err")"
    cmp=$("$compare" phantom-dvr.exr "$out") || fail "nrrd ${enc%%:*} -np 3: $cmp"
  done
  # Resident memory: a 256^3 u16 volume (32 MiB) on 4 ranks; each rank's peak above the
  # peak of the same run on a 64^3 volume (the process and MPI baseline) stays within
  # 3 x its slab (dense slab + bricked copy), far below the 2 x 32 MiB one process needs.
  "$rtfact" gen volume phantom --size 256 --quiet -o big.mhd || fail "gen big"
  for v in phantom big; do
    timeout 300 "${launch[@]}" -np 4 "$rtfact" volume "$v.mhd" "${vcommon[@]}" --distribute data --stats \
      -o "$v-mem.exr" >"$v-mem.stats" 2>"$v-mem.err" || fail "$v memory run: $(cat "$v-mem.err")"
  done
  for r in 0 1 2 3; do
    small=$(stat_of phantom-mem.stats "rank${r}_vmhwm_kb") big=$(stat_of big-mem.stats "rank${r}_vmhwm_kb")
    loaded=$(stat_of big-mem.stats "rank${r}_loaded_bytes")
    echo "rank $r: VmHWM ${small} kB (64^3) ${big} kB (256^3), slab ${loaded} bytes"
    [ $((loaded)) -le $((32 * 1024 * 1024 / 4 + 6 * 256 * 256 * 2)) ] || fail "rank $r loaded $loaded bytes of 32 MiB"
    [ $(((big - small) * 1024)) -le $((3 * loaded)) ] ||
      fail "rank $r: VmHWM grew by $(((big - small) / 1024)) MiB for a slab of $((loaded / 1048576)) MiB"
  done
elif [ "$what" = data_failing ]; then
  "$rtfact" gen volume phantom --size 64 --quiet -o cut.mhd || fail "gen"
  # Cut the last 3 slices: the last of 4 ranks (planes 47..63 plus ghosts) lacks its
  # slab, the others (up to plane 50) have theirs.
  truncate -s $((61 * 64 * 64 * 2)) cut.raw
  timeout 120 "${launch[@]}" -np 4 "$rtfact" volume cut.mhd --size 64x48 --threads 1 --quiet --distribute data \
    -o cut.png >cut.out 2>cut.err
  rc=$?
  [ "$rc" = 124 ] && fail "truncated volume: mpirun hung (timeout)"
  [ "$rc" = 1 ] || fail "truncated volume: mpirun exited $rc, want 1"
  lines=$(grep -c "^rtfact: error:" cut.err)
  [ "$lines" = 1 ] || fail "truncated volume: $lines error lines, want 1: $(cat cut.err)"
  grep -q "^rtfact: error: rank 3: .*cut.raw" cut.err || fail "truncated volume: the line does not name rank 3: $(cat cut.err)"
  [ -e cut.png ] && fail "truncated volume: an image was written"
  # Image-parallel needs the whole file on every rank: rank 0 names it.
  timeout 120 "${launch[@]}" -np 2 "$rtfact" volume cut.mhd --size 64x48 --threads 1 --quiet --distribute image \
    -o cut.png >/dev/null 2>cut-image.err
  grep -q "^rtfact: error: rank 0: .*cut.raw" cut-image.err || fail "image-parallel on a cut file: $(cat cut-image.err)"
elif [ "$what" = identical ]; then
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
  timeout 120 "${launch[@]}" -np 2 "$rtfact" mesh "$data/meshes/bunny.ply" "${common[@]}" --distribute data \
    -o data.png >/dev/null 2>data.err
  rc=$?
  [ "$rc" = 2 ] || fail "--distribute data for a mesh: exit $rc, want 2"
  grep -q "data-parallel rendering is for volumes and point clouds" data.err ||
    fail "--distribute data for a mesh: no usage message in: $(cat data.err)"
fi
[ "$fails" = 0 ] && echo "mpi $what $scene: ok"
exit $((fails > 0))
