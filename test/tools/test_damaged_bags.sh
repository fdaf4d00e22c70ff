#!/usr/bin/env bash
# map_from_bag on damaged bags (test/tools/damage_bag.py damages the small drive of
# test/tools/make_test_bag.py, 25 masks in lz4 chunks, one mask per chunk):
#  - cut at 90 % (no index): mapped without reindexing (its chunks read in record order), one
#    stderr line and the summary say so, >= 80 % of the frames and as many as the reindexed
#    bag; cut after its first records (nothing readable): one line suggesting `rosbag
#    reindex`, exit 2;
#  - never closed (index position 0): mapped the same way, every frame;
#  - two corrupt chunks (bytes flipped in their lz4 data): exit 0, the frames of the other
#    chunks mapped, the lost spans (those of the chunks) on stderr, in summary.txt and in
#    map.json metadata;
#  - the same with bz2 chunks (the drive rewritten: odometry now in every chunk), the lost
#    spans those of the two chunks;
#  - random bytes flipped anywhere after the file header (8 seeds): exit 0 with every mask
#    accounted for, or exit 2 with one line.
# No run ends with a signal. Run by ctest in the devel space's environment.
set -eo pipefail
export PATH="/usr/bin:/bin:$PATH"
repo="${IRM_SOURCE_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
work="$(mktemp -d /tmp/irm_damaged_bags_XXXXXX)"
trap 'rm -rf "$work"' EXIT
export ROS_HOME="$work/ros_home"
failures=0

fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok: $*"; }
damage() { /usr/bin/python3 "$repo/test/tools/damage_bag.py" "$@"; }

# Runs map_from_bag on $1 into $2; sets rc (a signal shows as rc > 128).
run_mapper() {
  rc=0
  rosrun ipm_road_mapper map_from_bag --bag "$1" --out "$2" >"$2.stdout" 2>"$2.stderr" || rc=$?
  if [ "$rc" -gt 128 ]; then fail "$1: killed by signal $((rc - 128))"; fi
}

# Expects exit 2 with exactly one stderr line suggesting `rosbag reindex <bag>` and $2.
expect_reindex_line() {
  local bag="$1" why="$2"
  run_mapper "$bag" "$work/$(basename "$bag" .bag)"
  local err="$work/$(basename "$bag" .bag).stderr"
  if [ "$rc" -ne 2 ]; then
    fail "$bag: exit $rc, expected 2: $(cat "$err")"
  elif [ "$(wc -l <"$err")" -ne 1 ]; then
    fail "$bag: $(wc -l <"$err") stderr lines, expected one:"; cat "$err"
  elif ! grep -q -- "rosbag reindex $bag" "$err" || ! grep -q -- "$why" "$err"; then
    fail "$bag: no 'rosbag reindex $bag' / '$why' in: $(cat "$err")"
  else
    pass "$(basename "$bag") -> exit 2: $(cat "$err")"
  fi
}

# Frames used / read from a summary.txt.
frames() { sed -n "s/^frames $1: \([0-9]*\)$/\1/p" "$2"; }

/usr/bin/python3 "$repo/test/tools/make_test_bag.py" "$work/drive.bag"

# Expects $1 (a bag without its index) mapped in record order: exit 0, one stderr line
# saying so, >= $3 frames used, the summary's index line naming $2.
expect_salvaged() {
  local bag="$1" why="$2" min_used="$3" name
  name="$(basename "$bag" .bag)"
  run_mapper "$bag" "$work/$name"
  local err="$work/$name.stderr" summary="$work/$name/summary.txt"
  used=$(frames used "$summary" 2>/dev/null || true)
  if [ "$rc" -ne 0 ]; then
    fail "$name: exit $rc, expected 0: $(tail -3 "$err")"
  elif ! grep -q "^map_from_bag: $bag: .*$why.*: read past the missing index in record order" "$err"; then
    fail "$name: no 'read past the missing index' line naming '$why' on stderr:"; cat "$err"
  elif [ -z "$used" ] || [ "$used" -lt "$min_used" ]; then
    fail "$name: frames used '${used}', expected >= $min_used"
  elif ! grep -q "^index: missing (.*$why" "$summary"; then
    fail "$name: no 'index: missing' line in summary.txt"
  elif ls -A "$work/$name" | grep -q "indexed.bag"; then
    fail "$name: the temporary indexed copy was left in the output folder"
  else
    pass "$name -> exit 0 without reindexing, $used of 25 frames used: $(grep '^index:' "$summary")"
  fi
}

# 1. Cut at 90 %: mapped without `rosbag reindex` (its chunks read in order), as many frames
#    as the reindexed bag gives.
damage truncate "$work/drive.bag" "$work/cut.bag" --fraction 0.9
expect_salvaged "$work/cut.bag" "truncated" 20
salvaged_used="$used"
cp "$work/cut.bag" "$work/cut_copy.bag"
rosbag reindex "$work/cut_copy.bag" >/dev/null 2>&1 || fail "rosbag reindex cut_copy.bag"
run_mapper "$work/cut_copy.bag" "$work/cut_reindexed"
used=$(frames used "$work/cut_reindexed/summary.txt" 2>/dev/null || true)
if [ "$rc" -eq 0 ] && [ -n "$used" ] && [ "$salvaged_used" -ge "$used" ]; then
  pass "reindexed cut bag: $used frames used, record order: $salvaged_used"
else
  fail "reindexed cut bag: exit $rc, frames used '${used}', record order '${salvaged_used}'"
fi
# Cut right after its first records: nothing readable, one line suggesting reindex, exit 2.
damage truncate "$work/drive.bag" "$work/stub.bag" --fraction 0.002
expect_reindex_line "$work/stub.bag" "truncated"

# 2. A recording that was never closed (index position 0): every chunk read in order.
damage unclose "$work/drive.bag" "$work/open.bag"
expect_salvaged "$work/open.bag" "no index" 23

# 3. Two corrupt chunks (mask chunks 8 and 16: stamps 0.93 s and 1.73 s after the start).
damage corrupt "$work/drive.bag" "$work/corrupt.bag" --chunks 8 16 >"$work/corrupted_chunks.txt"
cat "$work/corrupted_chunks.txt"
run_mapper "$work/corrupt.bag" "$work/corrupt"
if [ "$rc" -ne 0 ]; then
  fail "corrupt bag: exit $rc, expected 0: $(tail -3 "$work/corrupt.stderr")"
else
  # The spans of the corrupted chunks, as damage_bag.py printed them: "0.93-0.93 s, 1.73-1.73 s".
  spans=$(sed -n 's/^chunk [0-9]*: \(.*\)$/\1/p' "$work/corrupted_chunks.txt" | paste -sd, | sed 's/,/, /g')
  [ "$spans" = "0.93-0.93 s, 1.73-1.73 s" ] || fail "the test drive changed: corrupted chunks $spans"
  lost_line=$(grep "^map_from_bag: lost " "$work/corrupt.stderr" || true)
  if echo "$lost_line" | grep -qF "lost $spans of the bag (2 unreadable spans"; then
    pass "lost spans on stderr: $lost_line"
  else
    fail "no (or a wrong) lost line on stderr: '$lost_line'"; cat "$work/corrupt.stderr"
  fi
  read_n=$(frames read "$work/corrupt/summary.txt")
  used=$(frames used "$work/corrupt/summary.txt")
  if [ "$read_n" = 25 ] && [ "$used" -ge 20 ] && [ "$used" -le 23 ] &&
     grep -q "^  unreadable_chunk: 2$" "$work/corrupt/summary.txt" &&
     grep -q "^lost: 4 messages (2 masks) in 2 unreadable spans: 0.93-0.93 s, 1.73-1.73 s" \
       "$work/corrupt/summary.txt"; then
    pass "corrupt bag summary: 25 read, $used used, 2 unreadable_chunk, lost spans"
  else
    fail "corrupt bag summary:"; cat "$work/corrupt/summary.txt"
  fi
  /usr/bin/python3 - "$work/corrupt/map.json" <<'EOF2' || fail "map.json lost metadata"
import json, sys
meta = json.load(open(sys.argv[1]))["metadata"]
lost = meta["lost"]
assert lost["messages"] == 4 and lost["masks"] == 2, lost
spans = [(round(s["begin_s"], 2), round(s["end_s"], 2)) for s in lost["spans"]]
assert spans == [(0.93, 0.93), (1.73, 1.73)], spans
assert all(abs(s["begin_stamp"] - 1700000000.0 - s["begin_s"]) < 1e-3 for s in lost["spans"])
assert lost["first_error"], lost
m = json.load(open(sys.argv[1]))
assert len(m["markings"]) >= 1, "no marking mapped"
print(f"ok: map.json metadata lost: {lost['messages']} messages, spans {spans}; "
      f"{len(m['markings'])} markings mapped")
EOF2
fi

# 3b. bz2 chunks: the lost spans are the corrupted chunks' spans.
damage recompress "$work/drive.bag" "$work/drive_bz2.bag" --compression bz2
damage corrupt "$work/drive_bz2.bag" "$work/corrupt_bz2.bag" --chunks 8 16 >"$work/corrupted_bz2.txt"
spans=$(sed -n 's/^chunk [0-9]*: \(.*\)$/\1/p' "$work/corrupted_bz2.txt" | paste -sd, | sed 's/,/, /g')
run_mapper "$work/corrupt_bz2.bag" "$work/corrupt_bz2"
used=$(frames used "$work/corrupt_bz2/summary.txt" 2>/dev/null || true)
if [ "$rc" -eq 0 ] && grep -qF "map_from_bag: lost $spans of the bag (2 unreadable spans" \
     "$work/corrupt_bz2.stderr" && [ -n "$used" ] && [ "$used" -ge 20 ]; then
  pass "bz2 chunks: exit 0, lost $spans (the corrupted chunks), $used frames used"
else
  fail "bz2 chunks (exit $rc, chunks $spans, $used used):"; grep -v frames/s "$work/corrupt_bz2.stderr"
fi

# 4. Fuzz: random bytes inverted (chunk data, chunk headers, the index). With the extrinsic
# from the config, so that a lost /tf_static does not end every run early.
config="$work/extrinsic.yaml"
{ echo "base: $repo/config/mapper.yaml"; echo "backend: {enabled: false}"
  echo "input: {extrinsic: {xyz: [1.0, 0.0, 1.5], rpy_deg: [-95.0, 0.0, -90.0]}}"; } >"$config"
outcomes=""
for seed in 1 2 3 4 5 6 7 8; do
  damage flip "$work/drive.bag" "$work/fuzz.bag" --seed "$seed" --count 4
  rc=0
  rosrun ipm_road_mapper map_from_bag --bag "$work/fuzz.bag" --config "$config" --out "$work/fuzz" \
    >/dev/null 2>"$work/fuzz.stderr" || rc=$?
  if [ "$rc" -eq 0 ]; then
    grep -q "^frames read: 25$" "$work/fuzz/summary.txt" || fail "fuzz seed $seed: frames read is not 25"
  elif [ "$rc" -eq 2 ]; then
    [ "$(wc -l <"$work/fuzz.stderr")" -eq 1 ] && grep -q "^map_from_bag: error: " "$work/fuzz.stderr" \
      || { fail "fuzz seed $seed: exit 2 without exactly one error line:"; cat "$work/fuzz.stderr"; }
  else
    fail "fuzz seed $seed: exit $rc (a signal when > 128): $(tail -2 "$work/fuzz.stderr")"
  fi
  outcomes="$outcomes $rc"
  rm -rf "$work/fuzz"
done
pass "fuzz: exit codes$outcomes (0: mapped, every mask accounted for; 2: one line)"

# 5. The intact bag: nothing lost, and said so.
run_mapper "$work/drive.bag" "$work/intact"
if [ "$rc" -eq 0 ] && ! grep -q "^map_from_bag: lost" "$work/intact.stderr" &&
   grep -q "^lost: 0 messages (0 masks) in 0 unreadable spans: none$" "$work/intact/summary.txt" &&
   /usr/bin/python3 -c "import json,sys; l=json.load(open(sys.argv[1]))['metadata']['lost']; assert l['messages']==0 and l['spans']==[], l" \
     "$work/intact/map.json"; then
  pass "intact bag: nothing lost"
else
  fail "intact bag (exit $rc):"; grep -e "^lost" -e "^frames" "$work/intact/summary.txt"
fi

if [ "$failures" -ne 0 ]; then
  echo "$failures check(s) failed"
  exit 1
fi
echo "all damaged-bag checks passed"
