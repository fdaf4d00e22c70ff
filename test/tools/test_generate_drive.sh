#!/usr/bin/env bash
# End-to-end test of generate_drive: a short drive of the default scenario gives a bag with
# the five topics in the documented conventions and a parseable, deterministic ground truth;
# bad input gives exit code 2 and one error line; --help lists every option. Runs in the devel space's environment
# (ctest) or by hand after `source <devel>/setup.bash`.
set -eo pipefail

src="${IRM_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export ROS_HOME="$work/ros_home"

# The tool as `generate_drive` runs it; catkin_find also works under
# ctest, where ROS_PACKAGE_PATH does not list the source folder.
tool_bin=$(catkin_find --first-only --libexec ipm_road_mapper generate_drive 2>/dev/null) ||
  fail "ipm_road_mapper/generate_drive not found (source the devel space's setup.bash)"
generate_drive() { "$tool_bin" "$@"; }

scenario="$src/config/scenarios/public_road.yaml"
frames=40

# --- A short drive, twice with the same seed and once with another -----------------------
generate_drive --scenario "$scenario" --seed 3 --out "$work/a" \
  --max-frames $frames > "$work/a.log" || fail "generate_drive failed: $(cat "$work/a.log")"
cat "$work/a.log"
grep -q "plain IPM marking error" "$work/a.log" || fail "no IPM error line in the summary"
generate_drive --scenario "$scenario" --seed 3 --out "$work/b" \
  --max-frames $frames > /dev/null || fail "second run failed"
generate_drive --scenario "$scenario" --seed 4 --out "$work/c" \
  --max-frames $frames > /dev/null || fail "third run failed"
for f in drive.bag ground_truth.json trajectory_true_tum.txt trajectory_odom_tum.txt; do
  [ -s "$work/a/$f" ] || fail "missing output $f"
done
cmp -s "$work/a/ground_truth.json" "$work/b/ground_truth.json" \
  || fail "same seed gave different ground_truth.json"
cmp -s "$work/a/trajectory_odom_tum.txt" "$work/b/trajectory_odom_tum.txt" \
  || fail "same seed gave different odometry"
cmp -s "$work/a/trajectory_odom_tum.txt" "$work/c/trajectory_odom_tum.txt" \
  && fail "different seeds gave the same odometry"
[ "$(wc -l < "$work/a/trajectory_true_tum.txt")" -eq $frames ] || fail "TUM file length"

# --- Bag content and ground truth ------------------------------------------------------------
/usr/bin/python3 - "$work/a" $frames <<'EOF' || fail "bag/ground-truth check failed"
import json, sys
import rosbag

out, frames = sys.argv[1], int(sys.argv[2])
gt = json.load(open(out + "/ground_truth.json"))
assert len(gt["frames"]) == frames, len(gt["frames"])
assert gt["markings"] and gt["lanes"], "empty ground truth"

counts, stamps = {}, {}
with rosbag.Bag(out + "/drive.bag") as bag:
    info = bag.get_type_and_topic_info()
    for conn in bag._get_connections():
        if conn.topic == "/tf_static":
            assert conn.header.get("latching") in ("1", b"1"), "tf_static is not latched"
    for topic, msg, t in bag.read_messages():
        counts[topic] = counts.get(topic, 0) + 1
        if topic == "/tf_static":
            tf = msg.transforms[0]
            assert (tf.header.frame_id, tf.child_frame_id) == ("base_link", "camera_optical")
            continue
        stamp = msg.header.stamp.to_nsec()
        assert stamp > 0 and stamp == t.to_nsec(), (topic, stamp, t)
        stamps.setdefault(topic, []).append(stamp)
        if topic == "/camera/instances":
            assert msg.encoding == "16UC1" and msg.width == 1280 and msg.height == 720
            assert msg.step == 2 * 1280 and len(msg.data) == 2 * 1280 * 720
            assert msg.header.frame_id == "camera_optical"
        elif topic == "/camera/image_raw":
            assert msg.encoding == "mono8" and len(msg.data) == 1280 * 720
        elif topic == "/camera/camera_info":
            assert msg.distortion_model == "plumb_bob" and len(msg.D) == 5 and msg.K[0] > 0
        elif topic == "/odom":
            assert (msg.header.frame_id, msg.child_frame_id) == ("odom", "base_link")

expected = {"/camera/camera_info": frames, "/camera/instances": frames,
            "/camera/image_raw": frames, "/tf_static": 1}
for topic, n in expected.items():
    assert counts.get(topic) == n, (topic, counts.get(topic), n)
duration = (frames - 1) / 20.0
assert abs(counts["/odom"] - 50 * (duration + 0.2)) <= 2, counts["/odom"]
cam = stamps["/camera/instances"]
assert cam == stamps["/camera/camera_info"] == stamps["/camera/image_raw"]
assert cam[0] == 1000 * 10**9 and all(b - a == 50 * 10**6 for a, b in zip(cam, cam[1:]))
assert not set(cam) & set(stamps["/odom"]), "odometry stamps equal camera stamps"
assert all(abs(f["stamp"] - c * 1e-9) < 1e-6 for f, c in zip(gt["frames"], cam))
print("bag ok:", counts)
EOF

# --- Bad input: exit code 2 and exactly one line on stderr -----------------------------------
classes="$src/config/classes.yaml"
expect_input_error() {
  local name="$1" pattern="$2"; shift 2
  set +e
  generate_drive "$@" > "$work/out.txt" 2> "$work/err.txt"
  local rc=$?
  set -e
  [ $rc -eq 2 ] || fail "$name: exit code $rc, expected 2 ($(cat "$work/err.txt"))"
  [ "$(wc -l < "$work/err.txt")" -eq 1 ] || fail "$name: stderr is not one line: $(cat "$work/err.txt")"
  grep -q -- "$pattern" "$work/err.txt" || fail "$name: '$pattern' not in: $(cat "$work/err.txt")"
  echo "ok: $name -> $(cat "$work/err.txt")"
}
sed 's/^  lane_width_m:/  lane_widht_m:/' "$scenario" > "$work/bad_key.yaml"
sed 's/class: arrow_left,/class: arow_left,/' "$scenario" > "$work/bad_class.yaml"
sed 's/^  lanes: 3/  lanes: -1/' "$scenario" > "$work/bad_value.yaml"
expect_input_error "missing file" "no such scenario" \
  --scenario "$work/nope.yaml" --seed 1 --out "$work/x" --classes "$classes"
expect_input_error "bad key" "road.lane_widht_m" \
  --scenario "$work/bad_key.yaml" --seed 1 --out "$work/x" --classes "$classes"
expect_input_error "unknown class" "arow_left" \
  --scenario "$work/bad_class.yaml" --seed 1 --out "$work/x" --classes "$classes"
expect_input_error "bad value" "road.lanes" \
  --scenario "$work/bad_value.yaml" --seed 1 --out "$work/x" --classes "$classes"
expect_input_error "missing argument" "missing --out" --scenario "$scenario" --seed 1
expect_input_error "bad seed" "seed" --scenario "$scenario" --seed x1 --out "$work/x"
expect_input_error "unknown option" "unknown argument '--fast'" \
  --scenario "$scenario" --seed 1 --out "$work/x" --fast
expect_input_error "bad --max-frames" "max-frames" \
  --scenario "$scenario" --seed 1 --out "$work/x" --max-frames 0
[ ! -e "$work/x" ] || fail "an output folder was created for bad input"

# --- The command line: --help names every option with its default, exit 0 -----------------
generate_drive --help > "$work/help.txt" 2> "$work/help.err" || fail "--help exited $?"
[ ! -s "$work/help.err" ] || fail "--help wrote to stderr: $(cat "$work/help.err")"
for option in --scenario --seed --out --classes --max-frames --help; do
  grep -q -- "$option" "$work/help.txt" || fail "--help does not name $option"
done
[ "$(grep -o -e "(default: " -e "(required)" "$work/help.txt" | wc -l)" -ge 5 ] ||
  fail "--help does not give every option's default: $(cat "$work/help.txt")"
echo "ok: --help names every option"
echo "PASS"
