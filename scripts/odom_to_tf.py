#!/usr/bin/python3
"""Broadcasts each nav_msgs/Odometry as the tf header.frame_id -> child_frame_id.

For the demo only: a real vehicle's odometry source already publishes this transform (the
mapper never does: base_link has its parent). The synthetic bags carry /odom but no
odom -> base_link on /tf, so rviz's TF display needs this relay to place the vehicle.
usage: rosrun ipm_road_mapper odom_to_tf.py [odom:=/odom]
"""
import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry


def main():
    rospy.init_node("odom_to_tf")
    broadcaster = tf2_ros.TransformBroadcaster()

    def relay(msg):
        t = TransformStamped()
        t.header = msg.header
        t.child_frame_id = msg.child_frame_id or "base_link"
        t.transform.translation.x = msg.pose.pose.position.x
        t.transform.translation.y = msg.pose.pose.position.y
        t.transform.translation.z = msg.pose.pose.position.z
        t.transform.rotation = msg.pose.pose.orientation
        broadcaster.sendTransform(t)

    rospy.Subscriber("odom", Odometry, relay, queue_size=100)
    rospy.spin()


if __name__ == "__main__":
    main()
