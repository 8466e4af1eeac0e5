#!/usr/bin/python3
"""rostest user_tools: the shipped launch files, rviz configs and URDF as a user's tools read them
(docs/ros_interface.md, "Robot model" and "Many carts")."""
import os
import unittest
import xml.etree.ElementTree as ElementTree

import roslaunch.config
import rospkg
import rostest
import yaml

PACKAGE = "birkhoff_cart"


class UserTools(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.package = rospkg.RosPack().get_path(PACKAGE)

    def path(self, *parts):
        return os.path.join(self.package, *parts)

    def test_two_carts_builds_its_world_frame_with_static_transform_publisher(self):
        config = roslaunch.config.load_config_default([self.path("launch", "two_carts.launch")], None, verbose=False)
        publishers = [node for node in config.nodes if (node.package, node.type) == ("tf2_ros", "static_transform_publisher")]
        self.assertEqual(len(publishers), 1, [(node.package, node.type) for node in config.nodes])
        self.assertEqual(publishers[0].args.split(), ["0", "6", "0", "0", "0", "0", "world", "cart2/map"])
        self.assertEqual([node.name for node in config.nodes if node.package == "rostopic"], [],
                         "a rostopic node depends on the python3 first on PATH")

    def pose_tool_topics(self, rviz_file):
        with open(self.path("rviz", rviz_file)) as file:
            tools = yaml.safe_load(file)["Visualization Manager"]["Tools"]
        return sorted(tool["Topic"] for tool in tools if tool["Class"] == "rviz/SetInitialPose")

    def test_every_rviz_config_has_a_pose_tool_per_cart(self):
        self.assertEqual(self.pose_tool_topics("cart.rviz"), ["/initialpose"])
        self.assertEqual(self.pose_tool_topics("two_carts.rviz"), ["/cart1/initialpose", "/cart2/initialpose"])

    def test_the_steering_joint_has_the_end_stops_as_limits(self):
        joint = [j for j in ElementTree.parse(self.path("urdf", "cart.urdf")).getroot().iter("joint")
                 if j.get("name") == "steering_joint"][0]
        self.assertEqual(joint.get("type"), "revolute")
        limit = joint.find("limit")
        self.assertIsNotNone(limit, "steering_joint has no <limit>")
        with open(self.path("config", "scenes", "steering_actuator.yaml")) as file:
            end_stop = yaml.safe_load(file)["steering_end_stops"]["angle"]  # [rad]
        self.assertEqual(float(limit.get("lower")), -end_stop)
        self.assertEqual(float(limit.get("upper")), end_stop)
        with open(self.path("config", "cmd_vel_controller.yaml")) as file:
            controller = yaml.safe_load(file)
        self.assertEqual(float(limit.get("velocity")), controller["steering"]["max_rate"])
        self.assertLessEqual(controller["steering"]["max_angle"], end_stop)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "user_tools", UserTools)
