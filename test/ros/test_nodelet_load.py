#!/usr/bin/python3
"""rostest: the mapper nodelet loads with valid parameters and is refused with bad ones."""
import subprocess
import unittest

import rospy
import rostest
from nodelet.srv import NodeletList


class NodeletLoadTest(unittest.TestCase):
    def list_loaded(self):
        rospy.wait_for_service("/manager/list", timeout=30)
        return rospy.ServiceProxy("/manager/list", NodeletList)().nodelets

    def test_loads_with_valid_config(self):
        deadline = rospy.Time.now() + rospy.Duration(30)
        while rospy.Time.now() < deadline and "/mapper" not in self.list_loaded():
            rospy.sleep(0.2)
        self.assertIn("/mapper", self.list_loaded())

    def test_refuses_unknown_key_and_bad_value(self):
        for name, key, value in (("bad_key", "ipm/max_rnage_m", "30.0"),
                                 ("bad_value", "ipm/max_range_m", "-3.0")):
            rospy.set_param("/%s/%s" % (name, key), float(value))
            result = subprocess.run(
                ["rosrun", "nodelet", "nodelet", "load", "ipm_road_mapper/MapperNodelet",
                 "manager", "--no-bond", "__name:=%s" % name],
                timeout=30, capture_output=True, text=True)
            self.assertNotEqual(result.returncode, 0, result.stdout + result.stderr)
            self.assertNotIn("/" + name, self.list_loaded())
        # The manager survived the refused loads.
        self.assertIn("/mapper", self.list_loaded())

    def test_refuses_a_synchronous_backend(self):
        # Solves in the mapping thread would stall the input: refused at onInit, no mapping.
        rospy.set_param("/sync_backend/backend/synchronous", True)
        result = subprocess.run(
            ["rosrun", "nodelet", "nodelet", "load", "ipm_road_mapper/MapperNodelet",
             "manager", "--no-bond", "__name:=sync_backend"],
            timeout=30, capture_output=True, text=True)
        self.assertNotEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertNotIn("/sync_backend", self.list_loaded())
        self.assertIn("/mapper", self.list_loaded())


if __name__ == "__main__":
    rospy.init_node("test_nodelet_load")
    rostest.rosrun("ipm_road_mapper", "nodelet_load", NodeletLoadTest)
