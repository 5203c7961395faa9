#!/usr/bin/env python3
"""Runtime tuning of a running driver_node (against robot_sim) through dynamic_reconfigure's own
Python client: start-up values as the initial values, changes that apply on the running loop (no
Reset, SEQ unbroken, odometry with the new geometry), and a refused value."""
import math
import threading
import time
import unittest

import actionlib
import rospy
import rostest
from dynamic_reconfigure.client import Client
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, JointState
from serial_robot_driver.msg import (FollowJointTrajectoryAction, FollowJointTrajectoryGoal,
                                     FollowJointTrajectoryResult, WheelCommand)
from trajectory_msgs.msg import JointTrajectoryPoint

NODE = "/driver_node"
TIMEOUT = 30.0  # s: generous, the machine is shared


def wait_for(condition, timeout=TIMEOUT, what="condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not rospy.is_shutdown():
        if condition():
            return
        time.sleep(0.02)
    raise AssertionError("timed out waiting for " + what)


class Recorder:
    """Every message of a topic, in arrival order."""

    def __init__(self, topic, msg_type):
        self.lock = threading.Lock()
        self.messages = []
        self.sub = rospy.Subscriber(topic, msg_type, self.on_message, queue_size=1000,
                                    tcp_nodelay=True)

    def on_message(self, msg):
        with self.lock:
            self.messages.append(msg)

    def count(self):
        with self.lock:
            return len(self.messages)

    def since(self, index):
        with self.lock:
            return list(self.messages[index:])

    def wait_for_more(self, index, n):
        wait_for(lambda: self.count() >= index + n, what="%d more on %s" % (n, self.sub.name))
        return self.since(index)


class Driver:
    """Publishes one cmd_vel at 20 Hz until stopped (the driver's timeout never sees a gap)."""

    def __init__(self, linear, angular):
        self.pub = rospy.Publisher(NODE.rsplit("/", 1)[0] + "/cmd_vel", Twist, queue_size=10)
        self.twist = Twist()
        self.twist.linear.x = linear
        self.twist.angular.z = angular
        self.running = True
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self):
        rate = rospy.Rate(20)
        while self.running and not rospy.is_shutdown():
            self.pub.publish(self.twist)
            rate.sleep()

    def stop(self):
        self.running = False
        self.thread.join()


def expect_unbroken(test, frames):
    """SEQ one apart (mod 256), no Reset: the base never lost its heartbeat. (Battery requests
    also take a SEQ: the launch file turns them off.)"""
    for previous, frame in zip(frames, frames[1:]):
        test.assertFalse(frame.reset_before, "a Reset went out at seq %d" % frame.seq)
        test.assertEqual(frame.seq, (previous.seq + 1) % 256, "SEQ jumped")


class RuntimeTuningTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_runtime_tuning")
        cls.base = Client(NODE + "/base", timeout=TIMEOUT)
        cls.imu = Client(NODE + "/imu", timeout=TIMEOUT)
        cls.trajectory = Client(NODE + "/trajectory", timeout=TIMEOUT)
        cls.servo_bus = Client(NODE + "/servo_bus", timeout=TIMEOUT)
        cls.servo_states = Recorder("/servo_states", JointState)
        cls.follow = actionlib.SimpleActionClient("/follow_joint_trajectory",
                                                  FollowJointTrajectoryAction)
        assert cls.follow.wait_for_server(rospy.Duration(TIMEOUT))
        cls.frames = Recorder("/wheel_command", WheelCommand)
        cls.odom = Recorder("/odom", Odometry)
        cls.imu_data = Recorder("/imu/data", Imu)
        # Connected: the heartbeat frames flow.
        cls.frames.wait_for_more(0, 10)

    def tune(self, client, **values):
        """The server's answer: what applies."""
        return client.update_configuration(values)

    def test_a_initial_values_are_what_the_node_was_started_with(self):
        base = self.base.get_configuration(timeout=TIMEOUT)
        self.assertAlmostEqual(base["max_wheel_speed"], 0.8)  # the .cfg says 1.0
        self.assertAlmostEqual(base["cmd_vel_timeout"], 0.6)
        self.assertAlmostEqual(base["wheel_separation"], 0.42)
        self.assertEqual(base["battery_warn_percent"], 25)
        self.assertFalse(base["speed_dithering"])
        self.assertAlmostEqual(base["wheel_diameter"], 0.25)  # not set: the driver's default
        imu = self.imu.get_configuration(timeout=TIMEOUT)
        self.assertAlmostEqual(imu["accel_scale"], 0.005)
        self.assertAlmostEqual(imu["gyro_scale"], 0.0010653)
        trajectory = self.trajectory.get_configuration(timeout=TIMEOUT)
        self.assertAlmostEqual(trajectory["goal_tolerance"], 0.07)  # the .cfg says 0.05
        self.assertAlmostEqual(trajectory["max_velocity"], 0.0)
        servo_bus = self.servo_bus.get_configuration(timeout=TIMEOUT)
        self.assertAlmostEqual(servo_bus["state_rate"], 2.0)  # the .cfg says 10
        self.assertAlmostEqual(servo_bus["timeout"], 0.05)
        # The parameter server holds the same.
        self.assertAlmostEqual(rospy.get_param(NODE + "/base/max_wheel_speed"), 0.8)
        self.assertAlmostEqual(rospy.get_param(NODE + "/base/wheel_diameter"), 0.25)

    def test_b_speed_limit_changed_while_driving(self):
        self.tune(self.base, max_wheel_speed=0.8)
        driver = Driver(2.0, 0.0)
        try:
            start = self.frames.count()
            wait_for(lambda: any(abs(f.left_speed - 0.8) < 1e-6 for f in self.frames.since(start)),
                     what="frames at the 0.8 m/s limit")
            answer = self.tune(self.base, max_wheel_speed=0.4)
            self.assertAlmostEqual(answer["max_wheel_speed"], 0.4)
            self.assertAlmostEqual(rospy.get_param(NODE + "/base/max_wheel_speed"), 0.4)
            after = self.frames.count()
            # The frame that may have been on its way as the answer came, then only the new limit.
            new = self.frames.wait_for_more(after, 10)[1:]
            for frame in new:
                self.assertAlmostEqual(frame.left_speed, 0.4, places=6)
                self.assertAlmostEqual(frame.right_speed, 0.4, places=6)
            expect_unbroken(self, self.frames.since(start))
        finally:
            driver.stop()
            self.tune(self.base, max_wheel_speed=0.8)

    def test_c_wheel_separation_changed_while_turning(self):
        driver = Driver(0.0, 1.0)
        try:
            start = self.frames.count()
            self.frames.wait_for_more(start, 10)
            # 1 rad/s at 0.42 m: the wheels at -/+ 0.21 m/s.
            self.assertAlmostEqual(self.frames.since(start)[-1].right_speed, 0.21, places=6)
            self.tune(self.base, wheel_separation=0.6)
            after = self.frames.count()
            frames = self.frames.wait_for_more(after, 10)[1:]
            for frame in frames:
                self.assertAlmostEqual(frame.right_speed, 0.3, places=6)
                self.assertAlmostEqual(frame.left_speed, -0.3, places=6)
            odom_start = self.odom.count()
            odom = self.odom.wait_for_more(odom_start, 25)[5:]
            # Odometry turns with the new separation: the commanded 1 rad/s (the ticks round the
            # wheel speeds down to whole ticks, 12 of 12.2 per period: 2 % less).
            rate = sum(o.twist.twist.angular.z for o in odom) / len(odom)
            self.assertAlmostEqual(rate, 1.0, delta=0.05)
            expect_unbroken(self, self.frames.since(start))
        finally:
            driver.stop()
            self.tune(self.base, wheel_separation=0.42)

    def test_d_shortened_cmd_vel_timeout(self):
        answer = self.tune(self.base, cmd_vel_timeout=0.1)
        self.assertAlmostEqual(answer["cmd_vel_timeout"], 0.1)
        start = self.frames.count()
        pub = rospy.Publisher("/cmd_vel", Twist, queue_size=1, latch=True)
        twist = Twist()
        twist.linear.x = 0.2
        pub.publish(twist)
        wait_for(lambda: any(f.left_ticks > 0 for f in self.frames.since(start)), what="moving")
        wait_for(lambda: self.frames.since(start)[-1].left_ticks == 0, what="stopped again")
        moving = [f for f in self.frames.since(start) if f.left_ticks > 0]
        # At 50 Hz, 0.1 s is 5 or 6 frames; the 0.6 s the node started with would be 30.
        self.assertLessEqual(len(moving), 12)
        pub.unregister()
        self.tune(self.base, cmd_vel_timeout=0.6)

    def test_e_invalid_values_are_refused_and_the_answer_shows_what_applies(self):
        answer = self.tune(self.base, cmd_vel_timeout=0.0)  # validate(): must be > 0
        self.assertAlmostEqual(answer["cmd_vel_timeout"], 0.6)
        self.assertAlmostEqual(rospy.get_param(NODE + "/base/cmd_vel_timeout"), 0.6)
        # Below battery_error_percent (10): a rule between two values.
        answer = self.tune(self.base, battery_warn_percent=5)
        self.assertEqual(answer["battery_warn_percent"], 25)
        # Outside the .cfg's range: dynamic_reconfigure clamps to it.
        answer = self.tune(self.base, battery_warn_percent=150)
        self.assertEqual(answer["battery_warn_percent"], 100)
        self.assertEqual(rospy.get_param(NODE + "/base/battery_warn_percent"), 100)
        answer = self.tune(self.base, battery_warn_percent=25)
        self.assertEqual(answer["battery_warn_percent"], 25)
        self.assertEqual(rospy.get_param(NODE + "/base/battery_warn_percent"), 25)

    def test_f_imu_scale_applies_to_the_next_frames(self):
        start = self.imu_data.count()
        before = self.imu_data.wait_for_more(start, 20)
        self.tune(self.imu, accel_scale=0.01)
        after_start = self.imu_data.count()
        after = self.imu_data.wait_for_more(after_start, 20)[2:]
        a = sum(m.linear_acceleration.z for m in before) / len(before)
        b = sum(m.linear_acceleration.z for m in after) / len(after)
        self.assertGreater(abs(a), 1.0)
        self.assertAlmostEqual(b / a, 2.0, delta=0.05)
        self.tune(self.imu, accel_scale=0.005)


    def follow_joint_1(self, position, seconds):
        self.feedback = 0
        goal = FollowJointTrajectoryGoal()
        goal.trajectory.joint_names = ["joint_1"]
        point = JointTrajectoryPoint()
        point.positions = [position]
        point.time_from_start = rospy.Duration(seconds)
        goal.trajectory.points = [point]
        self.follow.send_goal(goal, feedback_cb=self.on_feedback)

    def on_feedback(self, _):
        self.feedback += 1

    def finish(self):
        self.assertTrue(self.follow.wait_for_result(rospy.Duration(TIMEOUT)))
        return self.follow.get_result().error_code

    def test_g_trajectory_speed_limit_and_a_running_goal_goes_on(self):
        # 0.3 rad in 1 s is faster than 0.1 rad/s: refused before anything moves.
        self.assertAlmostEqual(self.tune(self.trajectory, max_velocity=0.1)["max_velocity"], 0.1)
        self.follow_joint_1(0.3, 1.0)
        self.assertEqual(self.finish(), FollowJointTrajectoryResult.INVALID_GOAL)
        # Raised: the same goal runs; retuning while it runs does not stop it.
        self.tune(self.trajectory, max_velocity=1.0)
        self.follow_joint_1(0.3, 2.0)
        wait_for(lambda: self.feedback >= 5, what="the goal running")  # changes fall mid-goal
        self.tune(self.trajectory, goal_tolerance=0.1, max_velocity=0.5)
        self.tune(self.base, max_wheel_speed=0.7)
        self.assertEqual(self.finish(), FollowJointTrajectoryResult.SUCCESSFUL)
        # Back where it started, under the new limit (0.3 rad in 1 s = 0.3 rad/s).
        self.follow_joint_1(0.0, 1.0)
        self.assertEqual(self.finish(), FollowJointTrajectoryResult.SUCCESSFUL)
        self.tune(self.trajectory, goal_tolerance=0.07, max_velocity=0.0)
        self.tune(self.base, max_wheel_speed=0.8)


    def test_h_servo_polling_rate_raised(self):
        def median_interval(messages):
            stamps = [m.header.stamp.to_sec() for m in messages]
            gaps = sorted(b - a for a, b in zip(stamps, stamps[1:]))
            return gaps[len(gaps) // 2]

        start = self.servo_states.count()
        slow = self.servo_states.wait_for_more(start, 4)
        answer = self.tune(self.servo_bus, state_rate=20.0)
        self.assertAlmostEqual(answer["state_rate"], 20.0)
        after = self.servo_states.count()
        fast = self.servo_states.wait_for_more(after, 12)[1:]
        # 2 Hz polls 0.5 s apart, 20 Hz 0.05 s apart (the node's own stamps; wide margins).
        self.assertGreater(median_interval(slow), 0.3)
        self.assertLess(median_interval(fast), 0.25)
        # A rate of 0 is refused (the rate in force stays); too many retries are clamped.
        self.assertAlmostEqual(self.tune(self.servo_bus, state_rate=0.0)["state_rate"], 20.0)
        self.assertEqual(self.tune(self.servo_bus, retries=50)["retries"], 10)
        self.tune(self.servo_bus, state_rate=2.0, retries=1)


    def test_i_speed_limit_cannot_be_switched_off(self):
        # 0 (once "no limit") is refused like any value the start-up check refuses; -1 is clamped
        # to the .cfg's minimum 0 first, then refused. The limit in force stays.
        for requested in (0.0, -1.0):
            answer = self.tune(self.base, max_wheel_speed=requested)
            self.assertAlmostEqual(answer["max_wheel_speed"], 0.8)
            self.assertAlmostEqual(rospy.get_param(NODE + "/base/max_wheel_speed"), 0.8)
        # And motion is still limited: 2 m/s asked, 0.8 m/s sent.
        driver = Driver(2.0, 0.0)
        try:
            start = self.frames.count()
            wait_for(lambda: any(abs(f.left_speed - 0.8) < 1e-6 for f in self.frames.since(start)),
                     what="frames at the 0.8 m/s limit")
            for frame in self.frames.since(start):
                self.assertLessEqual(frame.left_speed, 0.8 + 1e-6)
                self.assertLessEqual(frame.right_speed, 0.8 + 1e-6)
        finally:
            driver.stop()


if __name__ == "__main__":
    rostest.rosrun("serial_robot_driver", "test_runtime_tuning", RuntimeTuningTest)
