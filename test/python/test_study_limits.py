"""Bounded and safe on any input: the alias bomb refused in under a second and 100 MB, messages that
quote user data short, the runner's arguments checked at once (a bad --scheduler exits 2), and the
output directory's lock taken before anything in it moves."""
import os
import subprocess
import sys
import time

import pytest

from birkhoff_cart_study import cli
from birkhoff_cart_study.limits import QUOTE_LENGTH, quoted
from conftest import REPOSITORY
from test_study_schema import BOMB, RANDOM_CARTS

MEASURE_BOMB = """
import sys, time
sys.path.insert(0, %r)
from birkhoff_cart_study.study_yaml import read_study_yaml
from birkhoff_cart_study.limits import StudyError
start = time.monotonic()
try:
    read_study_yaml(sys.argv[1])
    print("accepted")
except StudyError as error:
    # The peak RSS of this process's own memory [kB]: VmHWM belongs to the address space exec made
    # (ru_maxrss keeps the forking parent's peak on Linux: a large pytest process read as this one's).
    with open("/proc/self/status") as status:
        peak = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
    print("refused", time.monotonic() - start, peak, str(error))
"""


@pytest.mark.parametrize("levels", [7, 9, 12])
def test_the_alias_bomb_is_refused_in_under_a_second_and_100_MB(levels, study_file):
    text = "name: bomb\nkind: work_precision\n" + "".join(
        "l%d: &l%d [%s]\n" % (i, i, ",".join(["*l%d" % (i - 1)] * 9 if i else ['"lol"'] * 9)) for i in range(levels))
    text += "description: [%s]\nexperiments: []\n" % ",".join(["*l%d" % (levels - 1)] * 9)
    path = study_file(text)
    assert os.path.getsize(path) < 1000
    result = subprocess.run([sys.executable, "-c", MEASURE_BOMB % os.path.join(REPOSITORY, "src"), path],
                            stdout=subprocess.PIPE, universal_newlines=True, timeout=60)
    verdict, seconds, max_rss_kb, message = result.stdout.split(" ", 3)
    assert verdict == "refused", result.stdout
    assert float(seconds) < 1.0
    assert int(max_rss_kb) < 100 * 1024
    assert "limits.MAX_VALUES" in message and len(message) < 400


def test_the_bomb_of_the_malformed_list_is_the_same_kind_of_file():
    assert BOMB.count("*l8") == 9 and len(BOMB) < 1000


def test_quoted_values_are_short_and_escaped():
    huge = "x" * 10 ** 6
    assert len(quoted(huge)) <= QUOTE_LENGTH + 3
    assert quoted("a\nb'c") == "'a\\nb\\'c'"
    assert quoted([[1] * 10] * 10 ** 6) == "a list of 1000000 values"
    assert quoted({"k": huge}) == "a map of 1 key"
    assert quoted(float("nan")) == ".nan" and quoted(True) == "true" and quoted(None) == "null"
    assert quoted(10 ** 5000) == "a number of 16610 bits"


@pytest.mark.parametrize("address", ["garbage", "tcp://", "tcp://host", "tcp://host:0", "tcp://host:70000",
                                     "http://127.0.0.1:8786", "tcp://a b:1", "tcp://127.0.0.1:8786/x", "tls://h:1"])
def test_a_bad_scheduler_address_exits_2_at_once(address, study_file, fake_bin_dir, tmp_path, capsys):
    start = time.monotonic()
    status = cli.main([study_file(RANDOM_CARTS), "--bin-dir", fake_bin_dir, "--scheduler", address,
                       "--output-dir", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 2, err
    assert err.startswith("study: --scheduler") and len(err.splitlines()) == 1, err
    assert time.monotonic() - start < 2.0
    assert not (tmp_path / "out").exists()


def test_an_unreachable_scheduler_exits_2_within_its_timeout(study_file, fake_bin_dir, tmp_path, capsys):
    import socket
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))  # a port of ours that nobody answers on
    port = listener.getsockname()[1]
    listener.close()
    start = time.monotonic()
    status = cli.main([study_file(RANDOM_CARTS), "--bin-dir", fake_bin_dir, "--scheduler", "tcp://127.0.0.1:%d" % port,
                       "--scheduler-timeout", "2", "--output-dir", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "cannot reach the scheduler at tcp://127.0.0.1:%d within 2 s" % port in err
    assert time.monotonic() - start < 20.0
    assert not os.path.exists(os.path.join(fake_bin_dir, "ran"))


def test_tls_needs_its_certificate_files(study_file, fake_bin_dir, tmp_path, capsys):
    status = cli.main([study_file(RANDOM_CARTS), "--bin-dir", fake_bin_dir, "--scheduler", "tls://127.0.0.1:8786",
                       "--tls-ca-file", str(tmp_path / "none.pem"), "--tls-cert", "c", "--tls-key", "k"])
    assert status == 2
    assert "--tls-ca-file: no such file" in capsys.readouterr().err


def test_the_lock_is_taken_before_fresh_moves_the_rows(study_file, fake_bin_dir, tmp_path, capsys):
    output = tmp_path / "out"
    holder = cli.OutputLock(str(output))  # a first runner writing this directory
    rows = output / "rows.jsonl"
    rows.write_text('{"task_id": "a", "outcome": "ok"}\n')
    status = cli.main([study_file(RANDOM_CARTS), "--bin-dir", fake_bin_dir, "--output-dir", str(output), "--fresh"])
    assert status == 2
    assert "another study runner is writing" in capsys.readouterr().err
    assert rows.read_text() == '{"task_id": "a", "outcome": "ok"}\n'  # the first runner's rows stay where they are
    assert not (output / "rows.jsonl.old").exists()
    holder.file.close()
