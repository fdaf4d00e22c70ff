"""Helpers shared by the package's Python rostest nodes (imported from their folder).

Waits use wall time (time.monotonic), never ROS time: under use_sim_time the clock stops
when the bag ends. Every wait is for a condition, with a generous timeout that names what
it waited for.
"""
import os
import subprocess
import sys
import threading
import time

import rosgraph
import rospy
import yaml
from diagnostic_msgs.msg import DiagnosticArray
from nodelet.srv import NodeletList, NodeletLoad, NodeletUnload
from sensor_msgs.msg import CameraInfo, Image

SOURCE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CONFIG = os.path.join(SOURCE_DIR, "config", "mapper.yaml")
sys.path.insert(0, os.path.join(SOURCE_DIR, "test", "tools"))
import make_test_bag as drive  # noqa: E402  (the small drive's camera and mask rendering)


def camera_info(stamp, fx=drive.FX):
    """The small drive's camera_info (fx overridable, e.g. NaN)."""
    info = CameraInfo(height=drive.HEIGHT, width=drive.WIDTH, distortion_model="plumb_bob",
                      D=[0.0] * 5, K=[fx, 0, drive.CX, 0, drive.FY, drive.CY, 0, 0, 1],
                      R=[1, 0, 0, 0, 1, 0, 0, 0, 1],
                      P=[fx, 0, drive.CX, 0, 0, drive.FY, drive.CY, 0, 0, 0, 1, 0])
    info.header.stamp = stamp
    info.header.frame_id = "camera_optical"
    return info


def mask_image(stamp, data, encoding="16UC1"):
    """A mask message of a numpy array (16UC1, or a 1-byte encoding such as mono8)."""
    height, width = data.shape[:2]
    bytes_per_pixel = 2 if encoding == "16UC1" else 1
    image = Image(height=height, width=width, encoding=encoding, is_bigendian=0,
                  step=width * bytes_per_pixel,
                  data=(data.astype("<u2") if bytes_per_pixel == 2 else data.astype("u1")).tobytes())
    image.header.stamp = stamp
    image.header.frame_id = "camera_optical"
    return image


def advertised_services():
    """Names of every service registered with the master."""
    return [entry[0] for entry in rosgraph.Master(rospy.get_name()).getSystemState()[2]]


def wait_for(condition, timeout_s, what, period_s=0.05):
    """Polls condition() until true; raises AssertionError naming `what` after timeout_s."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        if rospy.is_shutdown():
            break
        time.sleep(period_s)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout_s, what))


def load_config(**overrides):
    """config/mapper.yaml as a dict, with {"section/key": value} overrides."""
    with open(CONFIG) as f:
        config = yaml.safe_load(f)
    for path, value in overrides.items():
        node = config
        keys = path.split("/")
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        node[keys[-1]] = value
    return config


class Diagnostics:
    """The newest value of every (status name, key) on /diagnostics."""

    def __init__(self):
        self._lock = threading.Lock()
        self._status = {}
        self._sub = rospy.Subscriber("/diagnostics", DiagnosticArray, self._on_array, queue_size=50)

    def _on_array(self, msg):
        with self._lock:
            for status in msg.status:
                self._status[status.name] = (status.level, status.message,
                                             {kv.key: kv.value for kv in status.values})

    def value(self, status_name, key, default=None):
        with self._lock:
            entry = self._status.get(status_name)
            return entry[2].get(key, default) if entry else default

    def number(self, status_name, key):
        v = self.value(status_name, key)
        return float(v) if v is not None else 0.0

    def keys(self, status_name):
        with self._lock:
            entry = self._status.get(status_name)
            return dict(entry[2]) if entry else {}


class Manager:
    """A nodelet manager's load/unload/list services (no bond, as `nodelet load --no-bond`)."""

    def __init__(self, name="/manager", timeout_s=60):
        for service in ("load_nodelet", "unload_nodelet", "list"):
            rospy.wait_for_service("%s/%s" % (name, service), timeout=timeout_s)
        self._load = rospy.ServiceProxy(name + "/load_nodelet", NodeletLoad)
        self._unload = rospy.ServiceProxy(name + "/unload_nodelet", NodeletUnload)
        self._list = rospy.ServiceProxy(name + "/list", NodeletList)

    def load(self, name, params):
        """Sets `params` as the private parameters of `name` and loads the mapper nodelet."""
        rospy.set_param(name, params)
        return self._load(name=name, type="ipm_road_mapper/MapperNodelet", remap_source_args=[],
                          remap_target_args=[], my_argv=[], bond_id="").success

    def unload(self, name):
        return self._unload(name=name).success

    def loaded(self):
        return list(self._list().nodelets)


def run(command, timeout_s):
    """Runs a command; returns (exit code, stdout + stderr)."""
    result = subprocess.run(command, capture_output=True, text=True, timeout=timeout_s)
    return result.returncode, result.stdout + result.stderr
