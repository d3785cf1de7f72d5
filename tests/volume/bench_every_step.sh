#!/usr/bin/env bash
# rtfact-bench volume --no-adaptive-steps: RTfact marches every step (issue 17's per-sample
# rate), so on the shipped tooth CT with the translucent ramp it takes more samples than the
# default adaptive march (96,866 against 74,523 at 64x64, step 0.5), and says so in its view
# line; the default run does not.
# usage: bench_every_step.sh RTFACT_BENCH DATASETS_DIR
set -uo pipefail
bench="$1" data="$2"
fail() {
  echo "FAIL: $*"
  exit 1
}
args=(volume "$data/volumes/tooth_103x94x161_uint8.raw" --size 64x64 --frames 1 --threads 1 --no-peer --ref-step 0
  --tf "$data/volumes/translucent_ramp_paraview.json")
adaptive="$("$bench" "${args[@]}" 2>&1)" || fail "default run exited with $?: $adaptive"
every="$("$bench" "${args[@]}" --no-adaptive-steps 2>&1)" || fail "--no-adaptive-steps run exited with $?: $every"
echo "$adaptive"
echo "$every"
samples() { awk '$1 == "rtfact" && $2 == "1" { print $6 }' <<<"$1"; }
a="$(samples "$adaptive")" e="$(samples "$every")"
[[ "$a" =~ ^[0-9]+$ && "$e" =~ ^[0-9]+$ ]] || fail "no one-thread rtfact row with a sample count"
((e > a)) || fail "every step took $e samples, not more than the adaptive march's $a"
grep -q "(every step: no adaptive steps)" <<<"$every" || fail "the --no-adaptive-steps view line does not say every step"
grep -q "every step" <<<"$adaptive" && fail "the default view line says every step"
echo "PASS: $a adaptive samples, $e every step"
