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

echo "$passes passed, $fails failed"
[ $fails -eq 0 ]
