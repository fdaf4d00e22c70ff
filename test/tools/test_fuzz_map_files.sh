#!/usr/bin/env bash
# Bounded, seeded fuzzing of evaluate_map's inputs: 300 mutants (FUZZ_N) of a small map.json
# and of its ground_truth.json (byte flips, truncation, deep nesting, huge numbers, type
# swaps, duplicate keys, long arrays), each run as `evaluate_map --map M --ground-truth G`.
# Fails on any signal, timeout, exit code other than 0 or 2, or a refusal that is not one
# line; prints the count of each outcome. FUZZ_N=5000 FUZZ_SEED=k for a longer manual run.
set -e -o pipefail

work=$(mktemp -d /tmp/irm_test_fuzz_map_files.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}

evaluate_map_bin=$(catkin_find --first-only --libexec ipm_road_mapper evaluate_map 2>/dev/null) ||
  fail "ipm_road_mapper/evaluate_map not found (source the devel space's setup.bash)"
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

/usr/bin/python3 "$here/fuzz_map_files.py" --evaluate-map "$evaluate_map_bin" --work "$work" \
  --n "${FUZZ_N:-300}" --seed "${FUZZ_SEED:-1}" || fail "evaluate_map mishandled a mutant (above)"
echo "PASS"
