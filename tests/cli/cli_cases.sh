#!/usr/bin/env bash
# CLI behaviour of `rtfact`: exit codes (0 ok, 1 error, 2 usage), the one-line error
# format, --stats keys, and that failures never leave or damage output files.
# usage: cli_cases.sh RTFACT_BINARY WORK_DIR
set -u
rtfact="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fails=0 passes=0

# expect CODE STDERR_REGEX -- ARGS...
expect() {
  local code="$1" pattern="$2"
  shift 3
  local err
  err=$(timeout 120 "$rtfact" "$@" 2>&1 >/dev/null)
  local rc=$?
  if [ "$rc" -ne "$code" ] || ! grep -Eq -- "$pattern" <<<"$err"; then
    echo "FAIL: rtfact $* -> exit $rc (want $code), stderr: $err (want /$pattern/)"
    fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}

expect 2 "A subcommand is required|subcommand" -- 
expect 2 "^rtfact: error: --size: expected WxH" -- spheres --size 10 -o a.png
expect 2 "^rtfact: error: --size" -- spheres --size 0x5 -o a.png
expect 2 "^rtfact: error: --size" -- spheres --size 99999x5 -o a.png
expect 2 "^rtfact: error: --eye: expected three numbers" -- spheres --eye 1,2 -o a.png
expect 2 "^rtfact: error: --at: expected three numbers" -- spheres --at 1,2,nan -o a.png
expect 2 "^rtfact: error: --packet: must be one of" -- spheres --packet 3 -o a.png
expect 2 "^rtfact: error: .*--threads" -- spheres --threads -1 -o a.png
expect 2 "^rtfact: error: .*(--fov|fov)" -- spheres --fov 0 -o a.png
expect 2 "^rtfact: error: .*(unknown|extra|not expected|following argument)" -- spheres --bogus
expect 1 "^rtfact: error: /nonexistent/dir/x.png: output directory does not exist$" -- spheres -o /nonexistent/dir/x.png
expect 1 "^rtfact: error: x.bmpx: unsupported image format" -- spheres -o x.bmpx
expect 1 "^rtfact: error: .*output path is a directory" -- spheres -o "$work"
expect 1 "^rtfact: error: /nonexistent/file.ply: no such file or directory$" -- info /nonexistent/file.ply
expect 0 "" -- --help

# A failed run leaves an existing image untouched and no temporary files.
echo "previous image" > keep.png
expect 2 "rtfact: error" -- spheres --size 0x0 -o keep.png
if [ "$(cat keep.png)" != "previous image" ]; then echo "FAIL: failed run modified keep.png"; fails=$((fails + 1)); fi

# A good run: the image replaces the old one, --stats prints the required keys.
out=$("$rtfact" spheres --size 64x48 --quiet --stats -o keep.png 2>&1)
rc=$?
if [ $rc -ne 0 ]; then echo "FAIL: spheres run exited $rc: $out"; fails=$((fails + 1)); fi
for key in load_ms build_ms render_ms rays mrays_per_s threads packet; do
  if ! grep -Eq "^$key=[0-9.]+$" <<<"$out"; then echo "FAIL: --stats lacks $key"; fails=$((fails + 1)); fi
done
if [ "$(head -c 4 keep.png | od -An -c | tr -d ' ')" != "211PNG" ]; then echo "FAIL: keep.png is not a PNG"; fails=$((fails + 1)); fi
if ls -a | grep -q '\.tmp'; then echo "FAIL: temporary files left: $(ls -a)"; fails=$((fails + 1)); fi
# --quiet and non-terminal stderr: no progress output at all.
if [ -n "$("$rtfact" spheres --size 32x32 -o q.png 2>&1 >/dev/null)" ]; then
  echo "FAIL: progress printed although stderr is not a terminal"; fails=$((fails + 1))
fi

# Hostile inputs through every loader: exit 1, exactly one line naming the file, and no
# image left behind. (The loaders' own test suites cover many more cases each.)
hostile() {  # hostile FILE ARGS... : run rtfact ARGS, expect a one-line error about FILE
  local file="$1"
  shift
  rm -f hostile.png
  local err
  err=$(timeout 120 "$rtfact" "$@" -o hostile.png --quiet 2>&1 >/dev/null)
  local rc=$?
  local lines
  lines=$(printf '%s\n' "$err" | grep -c .)
  if [ $rc -ne 1 ] || [ "$lines" -ne 1 ] || [[ "$err" != "rtfact: error: $file: "* ]] || [ -e hostile.png ]; then
    echo "FAIL: rtfact $* -> exit $rc, $lines line(s): $err"
    fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}
mkdir -p emptydir
for ext in ply pcd xyz pts; do : > "empty.$ext"; hostile "empty.$ext" points "empty.$ext"; done
hostile emptydir points emptydir
printf '6.66667e+82\n0 0 0\n' > huge.pts        # found by fuzzing (float->int overflow)
hostile huge.pts points huge.pts
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n' > lying.ply
hostile lying.ply points lying.ply
printf 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\nnan 0 0\nnan 1 1\n' > nan.ply
hostile nan.ply points nan.ply
for ext in ply obj stl vtk vtp; do : > "mesh.$ext"; hostile "mesh.$ext" mesh "mesh.$ext"; done
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n' > badindex.ply
hostile badindex.ply mesh badindex.ply
for ext in mhd nrrd nhdr nii nii.gz vti vdb; do : > "vol.$ext"; hostile "vol.$ext" volume "vol.$ext"; done
head -c 1000 /dev/zero > vol.raw
hostile vol.raw volume vol.raw --dims 10,10,11 --type u8
expect 2 '^rtfact: error: --dims: .*too large' -- volume vol.raw --dims 100000,100000,100000 --type u16 -o hostile.png
printf 'ObjectType = Image\nNDims = 3\nDimSize = 0 5 5\nElementType = MET_UCHAR\nElementDataFile = vol.raw\n' > zero.mhd
hostile zero.mhd volume zero.mhd
printf '{"colors": [[0, 1, 1]]' > bad.json
hostile bad.json volume vol.raw --dims 10,10,10 --type u8 --tf bad.json
mkdir -p junkdicom && { head -c 128 /dev/zero; printf DICM; head -c 600 /dev/zero | tr '\0' 'x'; } > junkdicom/a.dcm
hostile junkdicom volume junkdicom
# Textures: VTK, libpng and friends print on stderr themselves; the user sees one line.
printf 'newmtl t\nKd 1 1 1\nmap_Kd tex.png\n' > quad.mtl
printf 'mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl t\nf 1/1 2/2 3/3\n' > quad.obj
hostile tex.png mesh quad.obj
printf '\211PNG\r\n\032\n\0\0\0\rIHDR\0\0\0\002\0\0\0\002\010\002\0\0\0' > tex.png
hostile tex.png mesh quad.obj

# Memory estimates checked before allocating (RTFACT_MEMORY_LIMIT caps what the machine has):
# a clear error naming the file, the need and the option that would help; no image left.
{ printf 'ply\nformat ascii 1.0\nelement vertex 10000\nproperty float x\nproperty float y\nproperty float z\nend_header\n'
  awk 'BEGIN { for (i = 0; i < 10000; ++i) print i % 100, int(i / 100), (i * 7) % 13 }'; } > cloud.ply
RTFACT_MEMORY_LIMIT=256K expect 1 '^rtfact: error: cloud.ply: needs .* for loading 10000 points but only 256 KiB are available \(subsample' -- points cloud.ply --size 8x8 -o hostile.png
RTFACT_MEMORY_LIMIT=1M expect 1 '^rtfact: error: cloud.ply: needs 1\.3 MiB for preparing and building 10000 points .*\(normal estimation is the largest part' -- points cloud.ply --size 8x8 -o hostile.png
{ printf 'ply\nformat ascii 1.0\nelement vertex 10000\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n'
  awk 'BEGIN { for (i = 0; i < 10000; ++i) print i % 100, int(i / 100), 0, 0, 0, 1 }'; } > cloudn.ply
RTFACT_MEMORY_LIMIT=768K expect 1 '^rtfact: error: cloudn.ply: needs 703 KiB for preparing .* \(subsample' -- points cloudn.ply --radius 0.5 --size 8x8 -o hostile.png
{ printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 10000\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n'
  awk 'BEGIN { for (i = 0; i < 10000; ++i) print "3 0 1 2" }'; } > big.ply
RTFACT_MEMORY_LIMIT=512K expect 1 '^rtfact: error: big.ply: needs .* for 10000 triangles and their BVH .*\(simplify the mesh' -- mesh big.ply --size 8x8 -o hostile.png
head -c 1000000 /dev/zero > mem.raw
RTFACT_MEMORY_LIMIT=1M expect 1 '^rtfact: error: mem.raw: needs 1\.9 MiB for the volume .*\(a sparse OpenVDB grid' -- volume mem.raw --dims 100,100,100 --type u8 --size 8x8 -o hostile.png
RTFACT_MEMORY_LIMIT=1M expect 1 '^rtfact: error: hostile.png: needs .* for a 1024x1024 framebuffer .*\(use a smaller --size\)' -- spheres --size 1024x1024 -o hostile.png
RTFACT_MEMORY_LIMIT=lots expect 1 "^rtfact: error: RTFACT_MEMORY_LIMIT: not a size: 'lots'" -- spheres --size 8x8 -o hostile.png
if [ -e hostile.png ]; then echo "FAIL: an image was written although memory checks failed"; fails=$((fails + 1)); fi

# NaN and Inf in numeric options: exit 2, naming the option, in a short message (CLI::Range
# let NaN through and printed its bounds in full). The inputs are valid, so a missing
# check shows as a render with exit 0.
{ printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n'
  printf '0 0 0\n1 0 0\n0 1 0\n'; } > three.ply
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' > tri.ply
head -c 1000 /dev/zero > opt.raw
option_error() {  # option_error OPTION ARGS... : exit 2, a short message naming OPTION and no other option
  local option="$1"
  shift
  local err
  err=$(timeout 120 "$rtfact" "$@" --size 8x8 --quiet -o opt.png 2>&1 >/dev/null)
  local rc=$?
  local first
  first=$(head -n 1 <<<"$err")
  local others
  others=$(grep -Eo -- '--[a-z-]+' <<<"$first" | grep -vx -- "$option")
  if [ $rc -ne 2 ] || [[ "$first" != "rtfact: error: "*"$option"* ]] || [ -n "$others" ] || [ ${#first} -gt 160 ]; then
    echo "FAIL: rtfact $* -> exit $rc (want 2 naming $option in a short line): $err"
    fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}
option_error --fov points three.ply --fov nan
option_error --radius-factor points three.ply --radius-factor nan
option_error --lod-quality points three.ply --lod-quality nan
option_error --radius points three.ply --radius nan
option_error --radius points three.ply --radius -1
option_error --radius points three.ply --radius inf
option_error --radius points three.ply --radius 1e300
option_error --radius points three.ply --radius 1e-50
option_error --level volume opt.raw --dims 10,10,10 --type u8 --level -1e39
option_error --level volume opt.raw --dims 10,10,10 --type u8 --level nan
option_error --level volume opt.raw --dims 10,10,10 --type u8 --level inf
option_error --iso volume opt.raw --dims 10,10,10 --type u8 --mode iso --iso nan
option_error --iso volume opt.raw --dims 10,10,10 --type u8 --iso inf
option_error --window volume opt.raw --dims 10,10,10 --type u8 --window nan
option_error --step volume opt.raw --dims 10,10,10 --type u8 --step inf
option_error --fov mesh tri.ply --fov nan
option_error --fov mesh tri.ply --fov inf
option_error --eye mesh tri.ply --eye nan,0,0
option_error --up mesh tri.ply --up 0,inf,0
option_error --up mesh tri.ply --up 0,0,0
option_error --light mesh tri.ply --light point:1,nan,1
option_error --material mesh tri.ply --material lambert:nan,1,1
option_error --material mesh tri.ply --material glass:nan --integrator whitted
option_error --material mesh tri.ply --material glass:1.5x --integrator whitted

# Named pipes as inputs: a reader opening one blocks until a writer comes, so every input
# is checked to be a regular file first: exit 1 at once with one line naming the pipe
# (timeout 20 makes a hang a failure instead of a blocked test).
mkdir -p pipes
pipe_case() {  # pipe_case FILE ARGS... : rtfact ARGS exits 1 with one line "rtfact: error: FILE: ..."
  local file="$1"
  shift
  local err
  err=$(timeout 20 "$rtfact" "$@" 2>&1 >/dev/null)
  local rc=$?
  local lines
  lines=$(printf '%s\n' "$err" | grep -c .)
  if [ $rc -ne 1 ] || [ "$lines" -ne 1 ] || [[ "$err" != "rtfact: error: $file: "* ]]; then
    echo "FAIL: rtfact $* -> exit $rc$([ $rc -eq 124 ] && echo ' (hung: killed after 20 s)'), $lines line(s): $err"
    fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}
for ext in xyz ply pcd pts; do mkfifo "pipes/cloud.$ext"; pipe_case "pipes/cloud.$ext" points "pipes/cloud.$ext" --quiet -o hostile.png; done
for ext in vdb vti nrrd nii mhd; do mkfifo "pipes/vol.$ext"; pipe_case "pipes/vol.$ext" volume "pipes/vol.$ext" --quiet -o hostile.png; done
mkfifo pipes/vol.raw
pipe_case pipes/vol.raw volume pipes/vol.raw --dims 10,10,10 --type u8 --quiet -o hostile.png
for ext in ply obj stl vtk; do mkfifo "pipes/mesh.$ext"; pipe_case "pipes/mesh.$ext" mesh "pipes/mesh.$ext" --quiet -o hostile.png; done
mkfifo pipes/tf.json
pipe_case pipes/tf.json volume opt.raw --dims 10,10,10 --type u8 --tf pipes/tf.json --quiet -o hostile.png
mkfifo pipes/info.ply
pipe_case pipes/info.ply info pipes/info.ply
mkfifo pipes/lib.mtl
printf 'mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > pipes/withmtl.obj
pipe_case pipes/lib.mtl mesh pipes/withmtl.obj --quiet -o hostile.png
if [ -e hostile.png ]; then echo "FAIL: an image was written for a named-pipe input"; fails=$((fails + 1)); fi

# Point clouds render with the core's Whitted and path integrators too.
expect 0 "" -- points three.ply --integrator whitted --size 16x16 --quiet -o whitted.png
expect 0 "" -- points three.ply --integrator path --spp 2 --size 16x16 --quiet -o path.png
for img in whitted.png path.png; do
  if [ "$(head -c 4 "$img" 2>/dev/null | od -An -c | tr -d ' ')" != "211PNG" ]; then echo "FAIL: $img not written"; fails=$((fails + 1)); fi
done

# Non-finite points are dropped with one warning line (none with --quiet); a cloud with
# no finite point is an error.
printf '0 0 0\n1 0 0\n0 1 0\nnan 0 0\n1 inf 0\n' > some_nan.xyz
expect 0 '^rtfact: warning: some_nan.xyz: 2 points with non-finite coordinates dropped$' -- points some_nan.xyz --size 16x16 -o nan_ok.png
if [ -n "$("$rtfact" points some_nan.xyz --size 16x16 --quiet -o nan_ok.png 2>&1 >/dev/null)" ]; then
  echo "FAIL: --quiet still printed the non-finite warning"; fails=$((fails + 1))
fi
printf 'nan 0 0\n1 inf 0\n' > all_nan.xyz
hostile all_nan.xyz points all_nan.xyz
# A texture given as a named pipe is refused, not read.
mkfifo pipes/tex.png
printf 'newmtl m\nmap_Kd tex.png\n' > pipes/tex.mtl
printf 'mtllib tex.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n' > pipes/textured.obj
pipe_case pipes/tex.png mesh pipes/textured.obj --quiet -o hostile.png

echo "$passes passed, $fails failed"
[ $fails -eq 0 ]
