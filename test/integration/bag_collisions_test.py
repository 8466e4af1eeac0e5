#!/usr/bin/python3
"""rostest bag_collisions: cart_sim's record belongs to one run and survives a crash
(docs/ros_interface.md, "The bag"; docs/hard_cases.md section 10), tried as a user would:
- two launches on one master (`roslaunch birkhoff_cart sim.launch fast:=false duration:=0` twice,
  6 s apart, one bag path): the second node records to its own file, the first node, stopped by
  the name clash, finishes its bag at the path; both are complete, gap-free from t = 0.01 s, with
  every instant their summaries count, and each summary names its bag where it is;
- a restart over a killed run's bag (SIGKILL, then the same ~bag_path, as `respawn` does): the
  killed run's "<path>.active" is kept aside byte for byte under its time, never truncated;
- a directory as ~bag_path: refused at start by name (exit 2), the directory left as it is;
- SIGKILL at any moment (three moments of a run at 30x real time): `rosbag reindex` recovers every
  chunk whose data was whole in the file, the /odom instants in them a gap-free prefix of the run."""
import glob
import os
import re
import shutil
import signal
import struct
import subprocess
import tempfile
import time
import unittest

import rosbag
import roslib.packages
import roslz4
import rospkg
import rospy
import rostest
from nav_msgs.msg import Odometry

PACKAGE = "birkhoff_cart"
RUN_LIMIT = 60.0          # [s of wall time], only against hangs
PUBLISH_RATE = 100.0      # cart_sim's default ~publish_rate [Hz of scene time]
STAMP_TOLERANCE = 1e-6    # [s]
LAUNCH_GAP = 6.0          # [s of scene time = wall time, real-time mode] between the two launches
FILE_HEADER_BYTES = 4117  # the version line and the padded file header a bag starts with [bytes]
OP_CHUNK, OP_CONNECTION, OP_MESSAGE = 5, 7, 2


def scene(name):
    return os.path.join(rospkg.RosPack().get_path(PACKAGE), "config", "scenes", name)


def cart_sim():
    return roslib.packages.find_node(PACKAGE, "cart_sim")[0]


def wait_until(condition, limit=RUN_LIMIT):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


def odom_stamps(path):
    with rosbag.Bag(path) as bag:
        return [t.to_sec() for _, _, t in bag.read_messages(topics=["/odom"])]


def gap_free_from_start(stamps):
    """'' when `stamps` are k/rate for k = 1..N, else where they are not."""
    for k, stamp in enumerate(stamps):
        if abs(stamp - (k + 1) / PUBLISH_RATE) > STAMP_TOLERANCE:
            return "message %d at t = %.6f s, expected %.6f s" % (k, stamp, (k + 1) / PUBLISH_RATE)
    return ""


def summary_field(text, pattern):
    match = re.search(pattern, text)
    return match.group(1) if match else None


def read_header(data, at):
    """One record header at `at`: its fields and where its data length word starts."""
    (length,) = struct.unpack_from("<I", data, at)
    at += 4
    end = at + length
    if end > len(data):
        raise ValueError("header cut short")
    fields = {}
    while at < end:
        (field_length,) = struct.unpack_from("<I", data, at)
        name, value = data[at + 4:at + 4 + field_length].split(b"=", 1)
        fields[name.decode()] = value
        at += 4 + field_length
    return fields, end


def whole_chunks(path):
    """What a killed recorder's file holds in chunks whose data is whole: (chunks, /odom messages)."""
    data = open(path, "rb").read()
    at = len(b"#ROSBAG V2.0\n")
    _, at = read_header(data, at)
    at += 4 + struct.unpack_from("<I", data, at)[0]  # the file header's padding
    chunks, odom, odom_connections = 0, 0, set()
    while at + 4 <= len(data):
        try:
            fields, at = read_header(data, at)
        except (ValueError, struct.error):
            break
        if at + 4 > len(data):
            break
        (length,) = struct.unpack_from("<I", data, at)
        at += 4
        if at + length > len(data):
            break
        if fields["op"][0] == OP_CHUNK:
            chunk = data[at:at + length]
            compression = fields["compression"].decode()
            if compression == "lz4":
                chunk = roslz4.decompress(chunk)
            elif compression != "none":
                raise AssertionError("unexpected compression " + compression)
            inside = 0
            while inside < len(chunk):
                record, inside = read_header(chunk, inside)
                if record["op"][0] == OP_CONNECTION and record["topic"] == b"/odom":
                    odom_connections.add(record["conn"])
                elif record["op"][0] == OP_MESSAGE and record["conn"] in odom_connections:
                    odom += 1
                inside += 4 + struct.unpack_from("<I", chunk, inside)[0]
            chunks += 1
        at += length
    return chunks, odom


def reindexed(path):
    """`rosbag reindex` on a copy of `path`: (chunks, /odom stamps) recovered."""
    copy = path + ".copy.bag"
    shutil.copyfile(path, copy)
    result = subprocess.run(["rosbag", "reindex", copy], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            universal_newlines=True, timeout=RUN_LIMIT)
    if result.returncode != 0:
        raise AssertionError("rosbag reindex failed: " + result.stdout)
    with rosbag.Bag(copy) as bag:
        chunks = len(bag._chunks)  # the chunk-info records reindex wrote
    return chunks, odom_stamps(copy)


class BagCollisions(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("bag_collisions_test", anonymous=True)
        cls.odom_time = 0.0  # [s of scene time]: the stamp of the last /odom heard
        rospy.Subscriber("/odom", Odometry, cls.on_odom, queue_size=10)

    @classmethod
    def on_odom(cls, message):
        cls.odom_time = message.header.stamp.to_sec()

    def setUp(self):
        self.directory = tempfile.mkdtemp(prefix="bag_collisions_")

    def tearDown(self):
        shutil.rmtree(self.directory, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.directory, name)

    def launch(self, name, bag):
        log = open(self.path(name + ".log"), "w")
        process = subprocess.Popen(["roslaunch", PACKAGE, "sim.launch", "fast:=false", "duration:=0",
                                    "bag_path:=" + bag, "summary_path:=" + self.path(name + ".summary")],
                                   stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        log.close()
        return process

    def text(self, name):
        with open(self.path(name)) as file:
            return file.read()

    def test_two_launches_on_one_master_keep_both_bags(self):
        bag = self.path("birkhoff_cart.bag")
        type(self).odom_time = 0.0
        first = self.launch("first", bag)
        try:
            self.assertTrue(wait_until(lambda: self.odom_time >= LAUNCH_GAP), "the first launch never ran")
            second = self.launch("second", bag)
            try:
                # The second cart_sim takes the name /cart_sim: the master shuts the first one down,
                # and the first launch (cart_sim required) ends with it.
                self.assertEqual(first.wait(RUN_LIMIT), 0, self.text("first.log")[-3000:])
                type(self).odom_time = 0.0
                self.assertTrue(wait_until(lambda: 0.0 < self.odom_time < LAUNCH_GAP and self.odom_time >= 2.0),
                                "the second launch never ran")
                second.send_signal(signal.SIGINT)  # Ctrl-C
                self.assertEqual(second.wait(RUN_LIMIT), 0, self.text("second.log")[-3000:])
            finally:
                if second.poll() is None:
                    second.kill()
        finally:
            if first.poll() is None:
                first.kill()
        bags = {}
        for name in ("first", "second"):
            summary = self.text(name + ".summary")
            path = summary_field(summary, r" Bag: (\S+) \(")
            self.assertIsNotNone(path, summary)
            self.assertTrue(os.path.isfile(path), "%s's summary names %s, which is not there" % (name, path))
            stamps = odom_stamps(path)
            self.assertEqual(gap_free_from_start(stamps), "", name)
            self.assertEqual(len(stamps), int(summary_field(summary, r"Published instants: (\d+)")), name)
            bags[name] = (path, stamps)
        self.assertEqual(bags["first"][0], bag)
        self.assertEqual(bags["second"][0], self.path("birkhoff_cart_pid%s.bag" %
                                                      re.search(r"_pid(\d+)\.bag", bags["second"][0]).group(1)))
        self.assertGreaterEqual(bags["first"][1][-1], LAUNCH_GAP)
        self.assertGreaterEqual(bags["second"][1][-1], 2.0)
        self.assertIn("is being recorded by another running node", self.text("second.log"))
        self.assertEqual(sorted(os.path.basename(p) for p in glob.glob(self.path("*.bag*"))),
                         sorted(os.path.basename(bags[name][0]) for name in bags))

    def test_a_restart_over_a_killed_runs_bag_keeps_it_aside_byte_for_byte(self):
        bag = self.path("respawned.bag")
        active = bag + ".active"
        arguments = [cart_sim(), "__name:=respawned_sim", "_scene:=" + scene("driven.yaml"), "_bag_path:=" + bag]
        with open(self.path("killed.log"), "w") as log:
            killed = subprocess.Popen(arguments + ["_fast:=true", "_real_time_factor:=10", "_duration:=0"],
                                      stdout=log, stderr=subprocess.STDOUT)
        try:
            # a finished chunk in the file (the first chunk goes out after ~5 s of scene time)
            self.assertTrue(wait_until(lambda: os.path.exists(active) and os.path.getsize(active) > FILE_HEADER_BYTES))
        finally:
            killed.kill()  # SIGKILL
            killed.wait()
        crash_record = open(active, "rb").read()
        restart = subprocess.run(arguments + ["_fast:=true", "_duration:=1"], stdout=subprocess.PIPE,
                                 stderr=subprocess.STDOUT, universal_newlines=True, timeout=RUN_LIMIT)
        self.assertEqual(restart.returncode, 0, restart.stdout)
        kept = glob.glob(self.path("respawned_????????-??????.bag.active"))
        self.assertEqual(len(kept), 1, os.listdir(self.directory))
        self.assertIn("kept it as " + kept[0], restart.stdout)
        self.assertEqual(open(kept[0], "rb").read(), crash_record, "the killed run's bag was changed")
        self.assertEqual(len(odom_stamps(bag)), 100)  # the restarted run's, complete at the path
        self.assertFalse(os.path.exists(active))
        chunks, stamps = reindexed(kept[0])
        self.assertGreaterEqual(chunks, 1)
        self.assertEqual(gap_free_from_start(stamps), "")

    def test_a_directory_as_bag_path_is_refused_by_name_and_left_as_it_is(self):
        directory = self.path("logs")
        os.mkdir(directory)
        with open(os.path.join(directory, "kept.txt"), "w") as file:
            file.write("kept")
        before = sorted(os.listdir(self.directory))
        result = subprocess.run([cart_sim(), "__name:=directory_sim", "_scene:=" + scene("driven.yaml"),
                                 "_duration:=1", "_bag_path:=" + directory],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                timeout=RUN_LIMIT)
        self.assertEqual(result.returncode, 2, result.stdout)
        self.assertIn("cannot record to %s: it is a directory" % directory, result.stdout)
        self.assertEqual(sorted(os.listdir(self.directory)), before)
        self.assertEqual(os.listdir(directory), ["kept.txt"])

    def test_sigkill_at_any_moment_loses_only_the_chunk_being_written(self):
        # Killed at three moments of a run at 30x real time (LZ4, 768 KiB chunks): a chunk of ~5.5 s of
        # scene time every ~0.18 s of wall time.
        for kill_after in (0.8, 1.5, 2.3):  # [s of wall time after the bag appeared]
            bag = self.path("killed_%g.bag" % kill_after)
            with open(self.path("killed_%g.log" % kill_after), "w") as log:
                process = subprocess.Popen([cart_sim(), "__name:=sigkill_sim", "_scene:=" + scene("driven.yaml"),
                                            "_fast:=true", "_real_time_factor:=30", "_duration:=0",
                                            "_bag_path:=" + bag],
                                           stdout=log, stderr=subprocess.STDOUT)
            try:
                self.assertTrue(wait_until(lambda: os.path.exists(bag + ".active")))
                time.sleep(kill_after)
            finally:
                process.kill()
                process.wait()
            chunks, odom = whole_chunks(bag + ".active")
            self.assertGreaterEqual(chunks, 2, "killed after %g s" % kill_after)
            recovered_chunks, stamps = reindexed(bag + ".active")
            print("[ measured ] SIGKILL after %g s: %d whole chunks (%d odom instants) in the file, rosbag reindex "
                  "recovered %d chunks (%d odom instants, t <= %.2f s)" %
                  (kill_after, chunks, odom, recovered_chunks, len(stamps), stamps[-1] if stamps else 0.0))
            self.assertEqual(recovered_chunks, chunks, "killed after %g s" % kill_after)
            self.assertEqual(len(stamps), odom, "killed after %g s" % kill_after)
            self.assertEqual(gap_free_from_start(stamps), "")


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "bag_collisions", BagCollisions)
