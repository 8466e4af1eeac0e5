#!/usr/bin/python3
"""rostest shipped_studies: every shipped study file, run end to end at its smoke size
(`scripts/study FILE --smoke`: a few tasks of every experiment, each kind's `smoke`) on a local
cluster of two workers, exits 0: every task ok (or refused by name where the study allows it),
every goal judged by a resolved reference, the report written. A new study file is a new case."""
import glob
import json
import os
import subprocess
import sys
import tempfile
import unittest

import rospkg
import rostest

PACKAGE = "birkhoff_cart"
RUN_LIMIT = 600  # [s] per study, only against hangs
ROOT = rospkg.RosPack().get_path(PACKAGE)
STUDY_FILES = sorted(glob.glob(os.path.join(ROOT, "bench", "studies", "*.yaml")) +
                     glob.glob(os.path.join(ROOT, "checks", "studies", "*.yaml")))


class ShippedStudiesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.directory = tempfile.mkdtemp(prefix="shipped_studies_")

    def run_smoke(self, path):
        name = os.path.splitext(os.path.basename(path))[0]
        output = os.path.join(self.directory, name)
        result = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "study"), path, "--smoke",
                                 "--workers", "2", "--output-dir", output], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, universal_newlines=True, timeout=RUN_LIMIT,
                                stdin=subprocess.DEVNULL)
        self.assertEqual(result.returncode, 0, "%s at smoke size:\n%s\n%s" % (name, result.stdout, result.stderr[-3000:]))
        with open(os.path.join(output, "rows.jsonl")) as f:
            rows = [json.loads(line) for line in f]
        self.assertTrue(rows)
        for row in rows:
            self.assertIn(row["outcome"], ("ok", "refused", "step_failed"), row)
        self.assertIn("study %s: %d tasks: " % (rows[0]["study"], len(rows)), result.stdout)
        self.assertNotIn("without a verdict", result.stdout)
        with open(os.path.join(output, "results.md")) as f:
            self.assertTrue(f.read().startswith("# Results: %s" % rows[0]["study"]))

    def test_there_are_study_files_to_run(self):
        self.assertGreaterEqual(len(STUDY_FILES), 5, STUDY_FILES)


def _case(path):
    def test(self):
        self.run_smoke(path)
    test.__doc__ = "%s runs green at its smoke size" % os.path.relpath(path, ROOT)
    return test


for _path in STUDY_FILES:
    setattr(ShippedStudiesTest, "test_smoke_%s" % os.path.splitext(os.path.basename(_path))[0], _case(_path))


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "shipped_studies", ShippedStudiesTest)
