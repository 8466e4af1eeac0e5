#!/usr/bin/python3
"""The doc test: every fenced command block of README.md and docs/*.md, run as a reader would.

Usage: /usr/bin/python3 checks/doc_commands.py [--devel DIR] [--page FILE ...] [--only ID ...]
                                               [--jobs N] [--list] [--junit FILE] [--keep]

Every fenced block carries its language (```bash, ```console, ```python, ```pycon; ```text, ```cpp,
```yaml and the like are shown, never run); an unlabelled block is an error, since a reader cannot
tell a command from its output. The command blocks of a page run in order, as a reader follows the
page (the certificates one block makes, the next one uses), in a scratch directory that holds a
copy of the repository's files and `.ws/devel`, the built devel space (--devel, default .ws/devel);
pages run in parallel (--jobs). Each block runs with that devel space's environment (as after
`source .ws/devel/setup.bash`), a private ROS master on a free port when it uses ROS, a virtual
display when it opens rviz, and a time limit (BLOCK_SECONDS). Within a block:

- a command runs to its end and must exit 0; a block of ```console shows commands after `$ ` and
  their output below them: every output line shown (but `...`) must appear, in order, in what the
  command printed (stdout and stderr);
- a command that runs until it is stopped (UNTIL_STOPPED: roslaunch, rostopic pub/echo, tf_echo,
  teleop_keyboard, rviz, Dask's scheduler and workers, a line ending in `&`) is started as in a
  terminal of its own (a pseudo-terminal), given time to come up (the ROS graph stops changing, or
  its output falls quiet), and left running while the next lines run; at the end of the block it
  must still run (or have exited 0), must not have printed a fatal line (FATAL_OUTPUT) and, if it
  shows data (rostopic echo, tf_echo), must have shown some; then it is stopped with SIGINT;
- `source`, `cd`, `export` and assignments are the block's shell state: they apply to every later
  command of the block;
- ```python runs with /usr/bin/python3; ```pycon runs its `>>>` lines in one interpreter and checks
  the shown output lines as a console block does.

A block that must not run in CI carries a visible marker in the paragraph right above it,
`*Not run by the doc test (WHY): WHAT CI RUNS INSTEAD.*`, where the second part names in backticks
a test or file that exists. The run fails when an unmarked block fails, a block is unlabelled, a
marker is malformed, or more than MAX_MARKED_SHARE of the command blocks are marked. Processes a
block started are stopped at its end (found by the block's own environment variable), and the
page's scratch directory is removed (--keep keeps it, with doc_commands.log of what ran).
"""
import argparse
import concurrent.futures
import dataclasses
import os
import pathlib
import pty
import re
import select
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client

REPO = pathlib.Path(__file__).resolve().parent.parent
# A block's time limit [s of wall time]. Two pages run at once (--jobs 2) on a 2-core machine: the
# study blocks (README's 3000 random carts, studies.md's scale study) each keep both cores busy, so
# when they overlap each takes about twice its time alone.
BLOCK_SECONDS = 480.0
MAX_MARKED_SHARE = 0.15      # of the command blocks
COMMAND_LANGUAGES = {"bash", "sh", "shell", "console", "python", "pycon"}
SHOWN_LANGUAGES = {"text", "cpp", "c++", "yaml", "json", "xml", "cmake", "diff", "math", "csv"}
MARKER = re.compile(r"^\*Not run by the doc test \(([^)]+)\): (.+)\*$", re.S)
MARKER_START = "*Not run by the doc test"

# Commands that run until they are stopped, as a reader runs them in a terminal of their own.
UNTIL_STOPPED = [
    re.compile(r"^roslaunch\b"),
    re.compile(r"^roscore\b"),
    re.compile(r"^rostopic (pub|echo|hz)\b(?!.*(\s-1\b|--once|\s-n\s))"),
    re.compile(r"^rosrun tf tf_echo\b"),
    re.compile(r"^rosrun tf2_tools echo\.py\b"),
    re.compile(r"^rosrun birkhoff_cart (teleop_keyboard|nodelet_manager)\b"),
    re.compile(r"^rosrun nodelet nodelet (load|manager|standalone)\b"),
    re.compile(r"^(xvfb-run\b.*\s)?rviz\b"),
    re.compile(r"^(dask-scheduler|dask-worker)\b"),
]
# What a command that shows data must have shown by the end of its block.
SHOWS_DATA = [
    (re.compile(r"^rostopic echo\b"), re.compile(r"^---", re.M), "no message"),
    (re.compile(r"^rosrun tf tf_echo\b"), re.compile(r"^At time", re.M), "no transform"),
    (re.compile(r"^rostopic hz\b"), re.compile(r"average rate"), "no rate"),
]
# Lines that mean a command failed even though it still runs.
FATAL_OUTPUT = re.compile(r"process has died|Traceback \(most recent call last\)|\[FATAL\]")
USES_ROS = re.compile(r"\b(roslaunch|rostopic|rosservice|rosnode|rosparam|roswtf|rosrun (tf|tf2_tools|nodelet)\b|"
                      r"rosrun birkhoff_cart (teleop_keyboard|nodelet_manager|cart_sim\b|cmd_vel_controller|"
                      r"steering_driver))")
USES_DISPLAY = re.compile(r"\brviz\b")
# A measured figure in shown output: a decimal, a power of ten, or a count of three digits or more.
FIGURE = re.compile(r"\d\.\d|\d[eE][-+]?\d|\b\d{3,}\b")
SHELL_STATE = re.compile(r"^(source\s|\.\s|cd\s|export\s|[A-Za-z_][A-Za-z0-9_]*=)")


@dataclasses.dataclass
class Block:
    page: str          # relative to the repository
    line: int          # of the opening fence, 1-based
    language: str
    text: str
    marker: str = ""   # the marker paragraph, if any
    ordinal: int = 0   # the block's number among its page's command blocks

    @property
    def ident(self):
        """A stable, readable name: page, ordinal, first program (pytest -k selects on it)."""
        first = first_program(self)
        page = re.sub(r"[^A-Za-z0-9]+", "_", pathlib.Path(self.page).stem)
        return f"{page}-{self.ordinal}-{first}"

    @property
    def where(self):
        return f"{self.page}:{self.line}"

    @property
    def runs(self):
        return self.language in COMMAND_LANGUAGES


@dataclasses.dataclass
class Outcome:
    block: Block
    status: str        # "passed", "failed", "marked", "shown"
    detail: str = ""
    seconds: float = 0.0


def first_program(block):
    """The program a block starts first (a launch file's name for roslaunch): its name's last part."""
    if block.language in ("python", "pycon"):
        return "python"
    assigned = {}
    for command, _ in commands_of(block):
        assignment = re.match(r"^(?:export\s+)?([A-Za-z_][A-Za-z0-9_]*)=(\S*)$", command)
        if assignment:
            assigned[assignment.group(1)] = assignment.group(2)
        if SHELL_STATE.match(command):
            continue
        command = re.sub(r"\$\{?([A-Za-z_][A-Za-z0-9_]*)\}?", lambda m: assigned.get(m.group(1), m.group(1)), command)
        try:
            words = shlex.split(command, comments=True)
        except ValueError:
            words = command.split()
        words = [word for word in words if not re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", word)] or ["block"]
        if words[0] in ("rosrun", "roslaunch") and len(words) > 2:
            word = words[2]
        elif words[0] in ("bash", "sh", "python3", "/usr/bin/python3"):
            arguments = [word for word in words[1:] if not word.startswith("-")]
            word = arguments[0] if arguments and "-c" not in words else pathlib.Path(words[0]).name
        else:
            word = words[0]
        return re.sub(r"[^A-Za-z0-9_]+", "_", pathlib.Path(word).stem).strip("_") or "block"
    return block.language


# --- reading the pages ---------------------------------------------------------------------------

FENCE = re.compile(r"^( *)(```+|~~~+)\s*([^\s`]*)")


def blocks_of(page_path, root=REPO):
    """The fenced blocks of one markdown page, each with the marker paragraph above it."""
    lines = pathlib.Path(page_path).read_text().split("\n")
    relative = os.path.relpath(page_path, root)
    blocks, index, ordinal = [], 0, 0
    while index < len(lines):
        opening = FENCE.match(lines[index])
        if not opening:
            index += 1
            continue
        indent, fence, language = len(opening.group(1)), opening.group(2), opening.group(3).lower()
        body, close = [], index + 1
        while close < len(lines) and not lines[close].strip().startswith(fence[:3]):
            body.append(lines[close][indent:] if lines[close][:indent].strip() == "" else lines[close])
            close += 1
        block = Block(relative, index + 1, language, "\n".join(body) + "\n", marker_above(lines, index))
        if block.runs:
            ordinal += 1
            block.ordinal = ordinal
        blocks.append(block)
        index = close + 1
    return blocks


def marker_above(lines, fence_index):
    """The paragraph right above a fence (blank lines between allowed), if it is a marker."""
    end = fence_index - 1
    while end >= 0 and not lines[end].strip():
        end -= 1
    start = end
    while start - 1 >= 0 and lines[start - 1].strip() and not FENCE.match(lines[start - 1]):
        start -= 1
    paragraph = " ".join(line.strip() for line in lines[start:end + 1])
    return paragraph if paragraph.startswith(MARKER_START) else ""


def default_pages(root=REPO):
    return [root / "README.md"] + sorted((root / "docs").glob("*.md"))


def shows_figures(block):
    """Does a console or pycon block show output that holds a measured figure? Those blocks print
    what the right-hand sides' bits decide (errors, evaluation counts): the bit-sensitive ones."""
    return block.language in ("console", "pycon") and any(
        FIGURE.search(line) for _, expected in commands_of(block) for line in expected)


def figure_blocks(blocks):
    """The command blocks that show figures, with the ROS-free command blocks above them on their
    pages (a later block may use the files an earlier one made), in page order: the doc test's
    bit-sensitive share, which CI runs again as another CPU (CMakeLists.txt)."""
    last_figure = {}
    for block in blocks:
        if block.runs and not block.marker and shows_figures(block):
            last_figure[block.page] = max(last_figure.get(block.page, 0), block.line)
    return [block for block in blocks
            if block.runs and block.line <= last_figure.get(block.page, 0)
            and (shows_figures(block) or not USES_ROS.search(block.text))]


def commands_of(block):
    """[(command, expected output lines)] of a shell or console block; continuation lines joined."""
    lines = block.text.rstrip("\n").split("\n")
    result = []
    console = block.language in ("console", "pycon")
    prompt = "$ " if block.language == "console" else ">>> "
    index = 0
    while index < len(lines):
        line = lines[index]
        if console:
            if not line.startswith(prompt):
                if result:
                    result[-1][1].append(line)
                index += 1
                continue
            line = line[len(prompt):]
        stripped = line.strip()
        if not console and (not stripped or stripped.startswith("#")):
            index += 1
            continue
        command = line
        while command.rstrip().endswith("\\") and index + 1 < len(lines):
            index += 1
            command = command.rstrip()[:-1] + " " + lines[index].strip()
        if block.language == "pycon":
            while index + 1 < len(lines) and lines[index + 1].startswith("... "):
                index += 1
                command += "\n" + lines[index][4:]
        result.append((command.strip() if block.language != "pycon" else command, []))
        index += 1
    return result


# --- running one block ---------------------------------------------------------------------------

def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def devel_environment(devel):
    """The environment after `source DEVEL/setup.bash`, Debian's python3 first on PATH."""
    base = dict(os.environ, PATH="/usr/bin:/bin:" + os.environ.get("PATH", ""))
    listing = subprocess.run(["bash", "-c", f"set +u; source {shlex.quote(str(devel))}/setup.bash && env -0"],
                             env=base, stdout=subprocess.PIPE, check=True).stdout.decode()
    environment = dict(item.split("=", 1) for item in listing.split("\0") if "=" in item)
    environment["PATH"] = "/usr/bin:/bin:" + environment.get("PATH", "")
    return environment


def tracked_files(root):
    listing = subprocess.run(["git", "-C", str(root), "ls-files", "-z"], stdout=subprocess.PIPE,
                             stderr=subprocess.DEVNULL)
    if listing.returncode == 0 and listing.stdout:
        return [name for name in listing.stdout.decode().split("\0") if name]
    skip = {".git", "build", "devel", "install", "output"}
    return [str(path.relative_to(root)) for path in root.rglob("*")
            if path.is_file() and not (set(path.relative_to(root).parts[:1]) & skip)
            and not path.relative_to(root).parts[0].startswith(".ws")]


def make_scratch(root, files, devel, parent):
    scratch = pathlib.Path(tempfile.mkdtemp(prefix="doc_block_", dir=parent))
    for name in files:
        source = root / name
        if source.is_file():
            target = scratch / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)
    (scratch / ".ws").mkdir()
    (scratch / ".ws" / "devel").symlink_to(devel)
    for part in ("home", "tmp", "ros_home"):
        (scratch / part).mkdir()
    return scratch


class Terminal:
    """A command running until stopped, on a pseudo-terminal of its own; its output collected."""

    def __init__(self, command, script, cwd, environment):
        self.command = command
        master, slave = pty.openpty()
        self.process = subprocess.Popen(["bash", "-c", script], cwd=cwd, env=environment, stdin=slave,
                                        stdout=slave, stderr=slave, start_new_session=True)
        os.close(slave)
        self.master = master
        self.chunks = []
        self.last_output = None
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        while True:
            try:
                ready, _, _ = select.select([self.master], [], [], 0.2)
                if ready:
                    data = os.read(self.master, 65536)
                    if not data:
                        break
                    self.chunks.append(data.decode(errors="replace"))
                    self.last_output = time.monotonic()
                elif self.process.poll() is not None:
                    break
            except OSError:
                break

    @property
    def output(self):
        return "".join(self.chunks).replace("\r\n", "\n")

    def stop(self):
        if self.process.poll() is None:
            signal_group(self.process.pid, signal.SIGINT)
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                signal_group(self.process.pid, signal.SIGKILL)
                self.process.wait()
        self.reader.join(timeout=2)
        try:
            os.close(self.master)
        except OSError:
            pass


def signal_group(pid, signum):
    try:
        os.killpg(pid, signum)
    except (ProcessLookupError, PermissionError):
        pass


def stop_processes_marked(variable, value):
    """SIGKILL every process whose environment holds variable=value: those the block started,
    also the ones that left its process groups (daemons, Dask's nannies)."""
    needle = f"{variable}={value}".encode()
    for entry in pathlib.Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            if needle in (entry / "environ").read_bytes().split(b"\0"):
                os.kill(int(entry.name), signal.SIGKILL)
        except (OSError, ValueError):
            pass


def master_state(uri):
    try:
        code, _, state = xmlrpc.client.ServerProxy(uri).getSystemState("/doc_commands")
        return repr(state) if code == 1 else None
    except (OSError, xmlrpc.client.Error):
        return None


def wait_until_up(terminal, master_uri, deadline):
    """Until the ROS graph stops changing for 2 s after the command joined it (a ROS command), or
    its output has been quiet for 2 s (another), or it exited; at most 40 s."""
    started = time.monotonic()
    limit = min(deadline, started + 40.0)
    before = master_state(master_uri) if master_uri else None
    last_state, stable_since = before, time.monotonic()
    on_the_graph = master_uri is not None and bool(USES_ROS.search(terminal.command))
    while time.monotonic() < limit and terminal.process.poll() is None:
        time.sleep(0.25)
        now = time.monotonic()
        if on_the_graph:
            state = master_state(master_uri)
            if state != last_state:
                last_state, stable_since = state, now
            elif state != before and now - stable_since >= 2.0:
                return
        elif terminal.last_output is not None and now - terminal.last_output >= 2.0:
            return


def expected_lines_missing(expected, output):
    """The first shown output line not found, in order, in `output` (None: all found). A line `...`
    stands for any lines, a `…` inside a line for any part of it."""
    actual = [line.rstrip() for line in output.replace("\r\n", "\n").split("\n")]
    position = 0
    for line in expected:
        line = line.rstrip()
        if not line.strip() or line.strip() in ("...", "…"):
            continue
        shown = re.compile(".*".join(re.escape(part) for part in line.split("…")))  # … elides part of a line
        while position < len(actual) and not shown.fullmatch(actual[position]):
            position += 1
        if position == len(actual):
            return line
        position += 1
    return None


def run_page_blocks(blocks, root, files, devel, environment, scratch_parent, display, keep=False, progress=print):
    """Runs the blocks of one page in order, in one scratch directory, as a reader follows the
    page (a later block may use the files an earlier one made); returns their outcomes."""
    scratch = make_scratch(root, files, devel, scratch_parent)
    outcomes = []
    try:
        for block in blocks:
            outcome = run_block(block, scratch, environment, display)
            progress(f"doc_commands: {outcome.status.upper():6} {block.ident} ({block.where}, {outcome.seconds:.0f} s)"
                     + (f"\n{outcome.detail}" if outcome.status == "failed" else ""))
            outcomes.append(outcome)
    finally:
        if not keep:
            shutil.rmtree(scratch, ignore_errors=True)
    return outcomes


def run_block(block, scratch, environment, display):
    started = time.monotonic()
    deadline = started + BLOCK_SECONDS
    token = f"{os.getpid()}_{block.ident}"
    env = dict(environment, HOME=str(scratch / "home"), TMPDIR=str(scratch / "tmp"),
               ROS_HOME=str(scratch / "ros_home"), BIRKHOFF_CART_WORKSPACE=str(scratch / ".ws"),
               MPLBACKEND="Agg", DOC_COMMANDS_BLOCK=token, PYTHONUNBUFFERED="1")
    env.pop("DISPLAY", None)
    env.pop("XAUTHORITY", None)  # the caller's cookie file belongs to another server
    uses_display = display is not None and bool(USES_DISPLAY.search(block.text))
    if uses_display:
        name = display.acquire()
        if name is None:
            return Outcome(block, "failed", "no virtual display: Xvfb did not start (scripts/setup.sh installs xvfb)", 0.0)
        env["DISPLAY"] = name
    terminals, master, log = [], None, []
    try:
        if USES_ROS.search(block.text):
            port = free_port()
            env["ROS_MASTER_URI"] = f"http://127.0.0.1:{port}"
            master = subprocess.Popen(["roscore", "-p", str(port)], cwd=scratch, env=env, stdin=subprocess.DEVNULL,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
            while master_state(env["ROS_MASTER_URI"]) is None:
                if time.monotonic() > started + 30 or master.poll() is not None:
                    return Outcome(block, "failed", "the private ROS master did not start", time.monotonic() - started)
                time.sleep(0.2)
        if block.language == "python":
            return finish(block, started, *run_foreground(["/usr/bin/python3", "-"], block.text, scratch, env,
                                                          deadline, log, "python block"))
        if block.language == "pycon":
            return run_pycon(block, scratch, env, deadline, started)
        state = []
        for command, expected in commands_of(block):
            if SHELL_STATE.match(command):
                state.append(command)
                continue
            background = command.endswith("&") and not command.endswith("&&")
            command = command[:-1].rstrip() if background else command
            script = "\n".join(state + [command])
            if background or any(pattern.match(command) for pattern in UNTIL_STOPPED):
                terminal = Terminal(command, script, scratch, env)
                terminals.append(terminal)
                wait_until_up(terminal, env.get("ROS_MASTER_URI"), deadline)
                if terminal.process.poll() not in (None, 0):
                    return Outcome(block, "failed", f"`{command}` exited {terminal.process.returncode} at once:\n"
                                   + tail(terminal.output), time.monotonic() - started)
                continue
            status, output = run_foreground(["bash", "-c", script], None, scratch, env, deadline, log, command)
            if status != 0:
                return Outcome(block, "failed", f"`{command}` exited {status}:\n" + tail(output),
                               time.monotonic() - started)
            missing = expected_lines_missing(expected, output)
            if missing is not None:
                return Outcome(block, "failed", f"`{command}` did not print the line shown:\n  {missing}\n"
                               f"it printed:\n" + tail(output, 40), time.monotonic() - started)
        if terminals:
            time.sleep(max(0.0, min(5.0, deadline - time.monotonic())))
        for terminal in terminals:
            problem = terminal_problem(terminal)
            if problem:
                if uses_display:
                    problem += display_diagnosis(display, env)
                return Outcome(block, "failed", problem, time.monotonic() - started)
        return Outcome(block, "passed", "", time.monotonic() - started)
    finally:
        for terminal in reversed(terminals):
            terminal.stop()
        if master is not None:
            signal_group(master.pid, signal.SIGINT)
            try:
                master.wait(timeout=10)
            except subprocess.TimeoutExpired:
                signal_group(master.pid, signal.SIGKILL)
                master.wait()
        stop_processes_marked("DOC_COMMANDS_BLOCK", token)
        with open(scratch / "doc_commands.log", "a") as record:
            record.write("\n".join(log) + "\n")


def terminal_problem(terminal):
    output = terminal.output
    status = terminal.process.poll()
    if status not in (None, 0):
        return f"`{terminal.command}` exited {status} before the end of the block:\n" + tail(output)
    fatal = FATAL_OUTPUT.search(output)
    if fatal:
        return f"`{terminal.command}` printed '{fatal.group(0)}':\n" + tail(output)
    for program, shown, what in SHOWS_DATA:
        if program.match(terminal.command) and not shown.search(output):
            return f"`{terminal.command}` showed {what} while the block ran:\n" + tail(output)
    return ""


def run_foreground(command, stdin_text, cwd, env, deadline, log, label):
    remaining = deadline - time.monotonic()
    if remaining <= 0:
        return 124, f"the block's time limit ({BLOCK_SECONDS:.0f} s) was reached before `{label}`"
    process = subprocess.Popen(command, cwd=cwd, env=env, stdin=subprocess.PIPE if stdin_text else subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True, text=True)
    try:
        output, _ = process.communicate(stdin_text, timeout=remaining)
    except subprocess.TimeoutExpired:
        signal_group(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        return 124, (output or "") + f"\n(stopped: the block's time limit of {BLOCK_SECONDS:.0f} s)"
    log.append(f"$ {label}\n{output}")
    return process.returncode, output


PYCON_HARNESS = r"""
import code, sys
console = code.InteractiveConsole()
for statement in sys.stdin.read().split("\0"):
    lines = statement.split("\n")
    for line in lines:
        console.push(line)
    console.push("")
"""


def run_pycon(block, scratch, env, deadline, started):
    commands = commands_of(block)
    status, output = run_foreground(["/usr/bin/python3", "-c", PYCON_HARNESS], "\0".join(c for c, _ in commands),
                                    scratch, env, deadline, [], "pycon block")
    if status != 0:
        return Outcome(block, "failed", f"the interpreter exited {status}:\n" + tail(output), time.monotonic() - started)
    missing = expected_lines_missing([line for _, shown in commands for line in shown], output)
    if missing is not None:
        return Outcome(block, "failed", f"the session did not print the line shown:\n  {missing}\nit printed:\n"
                       + tail(output, 40), time.monotonic() - started)
    return Outcome(block, "passed", "", time.monotonic() - started)


def finish(block, started, status, output):
    if status != 0:
        return Outcome(block, "failed", f"exited {status}:\n" + tail(output), time.monotonic() - started)
    return Outcome(block, "passed", "", time.monotonic() - started)


def display_diagnosis(display, env):
    """What a failed rviz block's reader needs: whether the display is still up, and the end of
    each rviz log roslaunch wrote under ROS_HOME (rviz's own messages: a crash, a lost display)."""
    name = env.get("DISPLAY", "")
    lines = [f"\nthe display {name}: " + ("accepts connections" if name and display_accepts(name[1:])
                                          else "does NOT accept connections")]
    lines += [f"\n{lost}" for lost in display.lost]
    for log in sorted(pathlib.Path(env.get("ROS_HOME", "/nonexistent"), "log").glob("**/rviz*.log")):
        lines.append(f"\n{log.name}:\n" + tail(log.read_text(errors="replace"), 15))
    return "".join(lines)


def tail(text, lines=25):
    kept = (text or "").rstrip().split("\n")[-lines:]
    return "\n".join("    " + line for line in kept)


# --- the whole run -------------------------------------------------------------------------------

def marker_problem(block, root):
    """Why a block's marker is malformed ('' when it is well formed or absent)."""
    if not block.marker:
        return ""
    match = MARKER.match(block.marker)
    if not match:
        return f"{block.where}: a marker reads `*Not run by the doc test (WHY): WHAT CI RUNS INSTEAD.*`"
    named = re.findall(r"`([^`]+)`", match.group(2))
    for name in named:
        word = name.split()[0]
        candidates = [root / word, *(root / "test" / part / f"{word}{suffix}"
                                     for part in ("integration", "unit", "ros_unit", "python")
                                     for suffix in ("", ".test", ".cpp", ".py"))]
        if any(path.exists() for path in candidates):
            return ""
    return f"{block.where}: the marker names no existing test or file in backticks as what CI runs instead"


def start_display(log_path=os.devnull):
    """A virtual X display for rviz (Xvfb, -displayfd picks a free number; -noreset: the server
    keeps its state when its last client leaves, so that the next rviz never meets a server in
    the middle of a reset); (process, ':N') once it accepts a connection, else (None, None). Its
    own messages go to log_path."""
    if not shutil.which("Xvfb"):
        return None, None
    read_end, write_end = os.pipe()
    with open(log_path, "ab") as log:
        process = subprocess.Popen(["Xvfb", "-displayfd", str(write_end), "-screen", "0", "1024x768x24", "-nolisten",
                                    "tcp", "-noreset"], pass_fds=(write_end,), stdout=log, stderr=log,
                                   start_new_session=True)
    os.close(write_end)
    # Xvfb writes the number, then a newline, then closes its end; closing ours after the number
    # alone made its second write fail, and Xvfb exits at once ("Cannot write display number to
    # fd"): every rviz block then met "could not connect to display". Read up to the newline.
    written = b""
    waited_until = time.monotonic() + 20
    while b"\n" not in written and time.monotonic() < waited_until:
        ready, _, _ = select.select([read_end], [], [], max(0.0, waited_until - time.monotonic()))
        chunk = os.read(read_end, 64) if ready else b""
        if not chunk:
            break
        written += chunk
    os.close(read_end)
    number = written.decode().strip()
    # And then until the server completes a connection setup.
    while number and not display_accepts(number) and time.monotonic() < waited_until and process.poll() is None:
        time.sleep(0.1)
    if not number or not display_accepts(number):
        process.kill()
        process.wait()
        return None, None
    return process, f":{number}"


def display_accepts(number):
    """Does X display :number complete an X11 connection setup on its socket
    (/tmp/.X11-unix/X<number>; no authorization, as the doc test's Xvfb needs none)?"""
    with socket.socket(socket.AF_UNIX) as connection:
        connection.settimeout(5)
        try:
            connection.connect(f"/tmp/.X11-unix/X{number}")
            # Setup request: byte order 'l', protocol 11.0, no authorization name or data.
            connection.sendall(b"l\0" + (11).to_bytes(2, "little") + bytes(8))
            return connection.recv(1) == b"\1"  # 1: Success (0: Failed, 2: Authenticate)
        except OSError:
            return False


class Display:
    """The doc test's virtual display, shared by the pages' threads: started when a block first
    needs it, and started again (its death named in the block's outcome) when it no longer
    accepts connections, so that one lost server does not fail every later rviz block."""

    def __init__(self, log_path):
        self.log_path = log_path
        self.process = None
        self.name = None
        self.lock = threading.Lock()
        self.lost = []

    def acquire(self):
        """':N' of a display that accepts connections now, or None without Xvfb."""
        with self.lock:
            if self.process is not None and (self.process.poll() is not None
                                             or not display_accepts(self.name[1:])):
                self.lost.append(f"the doc test's Xvfb on {self.name} was lost (exit status "
                                 f"{self.process.poll()}); started another")
                self.stop_locked()
            if self.process is None:
                self.process, self.name = start_display(self.log_path)
            return self.name

    def stop_locked(self):
        if self.process is not None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.process, self.name = None, None

    def stop(self):
        with self.lock:
            self.stop_locked()


def run_pages(pages, root=REPO, devel=None, jobs=2, only=None, keep=False, progress=print):
    """Runs every command block of `pages`; returns [Outcome] (one per block) and the problems of
    the pages themselves (unlabelled blocks, malformed markers)."""
    devel = pathlib.Path(devel or root / ".ws" / "devel").resolve()
    blocks = [block for page in pages for block in blocks_of(page, root)]
    problems = []
    for block in blocks:
        if not block.language:
            problems.append(f"{block.where}: a fenced block without a language: label it (bash, console, "
                            f"python, pycon to run it; text, cpp, yaml ... to show it)")
        elif not block.runs and block.language not in SHOWN_LANGUAGES:
            problems.append(f"{block.where}: unknown block language '{block.language}'")
        problem = marker_problem(block, root)
        if problem:
            problems.append(problem)
        if block.marker and not block.runs:
            problems.append(f"{block.where}: a marker above a block that is not a command")
    if only:
        blocks = [block for block in blocks if block.ident in only or block.where in only]
    outcomes = [Outcome(block, "marked" if block.marker else "shown", block.marker)
                for block in blocks if not block.runs or block.marker]
    to_run = [block for block in blocks if block.runs and not block.marker]
    files = tracked_files(root)
    environment = devel_environment(devel)
    scratch_parent = pathlib.Path(tempfile.mkdtemp(prefix="doc_commands_"))
    display = Display(scratch_parent / "xvfb.log") if any(USES_DISPLAY.search(b.text) for b in to_run) else None
    by_page = {}
    for block in to_run:
        by_page.setdefault(block.page, []).append(block)
    # The longest pages first, so that the pool ends together.
    pages_in_order = sorted(by_page.values(), key=lambda page_blocks: -len(page_blocks))
    try:
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            futures = [pool.submit(run_page_blocks, page_blocks, root, files, devel, environment, scratch_parent,
                                   display, keep, progress) for page_blocks in pages_in_order]
            for future in concurrent.futures.as_completed(futures):
                outcomes.extend(future.result())
    finally:
        if display is not None:
            display.stop()
        if not keep:
            shutil.rmtree(scratch_parent, ignore_errors=True)
    order = {id(block): index for index, block in enumerate(blocks)}
    outcomes.sort(key=lambda outcome: order[id(outcome.block)])
    return outcomes, problems


def counts(outcomes):
    commands = [o for o in outcomes if o.block.runs]
    marked = [o for o in commands if o.status == "marked"]
    return {"command blocks": len(commands), "run": len(commands) - len(marked),
            "passed": sum(o.status == "passed" for o in commands), "failed": sum(o.status == "failed" for o in commands),
            "marked": len(marked), "marked share": len(marked) / len(commands) if commands else 0.0,
            "shown": len(outcomes) - len(commands)}


def summary_line(outcomes):
    c = counts(outcomes)
    return (f"doc_commands: {c['command blocks']} command blocks: {c['run']} run ({c['passed']} passed, "
            f"{c['failed']} failed), {c['marked']} marked ({100 * c['marked share']:.1f} %, at most "
            f"{100 * MAX_MARKED_SHARE:.0f} %); {c['shown']} blocks shown, not run")


def write_junit(path, outcomes, problems):
    from xml.sax.saxutils import escape, quoteattr
    cases = [(o.block.ident, o.seconds, o.detail if o.status == "failed" else None, o.status == "marked")
             for o in outcomes if o.block.runs]
    cases += [("page_problems", 0.0, "\n".join(problems) or None, False)]
    failures = sum(1 for _, _, failure, _ in cases if failure)
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<testsuite name="doc_commands" tests="{len(cases)}" failures="{failures}" errors="0">']
    for name, seconds, failure, marked in cases:
        lines.append(f'  <testcase classname="doc_commands" name={quoteattr(name)} time="{seconds:.0f}">')
        if failure:
            lines.append(f"    <failure message={quoteattr(failure.splitlines()[0])}>{escape(failure)}</failure>")
        if marked:
            lines.append("    <system-out>marked: not run by the doc test</system-out>")
        lines.append("  </testcase>")
    lines.append("</testsuite>")
    pathlib.Path(path).write_text("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--devel", type=pathlib.Path, help="the built devel space (default: .ws/devel)")
    parser.add_argument("--page", type=pathlib.Path, nargs="*", help="pages (default: README.md, docs/*.md)")
    parser.add_argument("--only", nargs="*", help="block names (as --list prints them) or PAGE:LINE")
    parser.add_argument("--jobs", type=int, default=2, help="blocks run at once (default 2)")
    parser.add_argument("--list", action="store_true", help="list the blocks and what happens to each")
    parser.add_argument("--junit", type=pathlib.Path, help="also write one JUnit case per command block")
    parser.add_argument("--keep", action="store_true", help="keep the scratch directories (and a log in each)")
    arguments = parser.parse_args()
    pages = [page.resolve() for page in arguments.page] if arguments.page else default_pages()
    if arguments.list:
        for page in pages:
            for block in blocks_of(page):
                what = "marked" if block.marker else "run" if block.runs else "shown"
                print(f"{block.where:28} {block.language or '(none)':8} {what:6} {block.ident if block.runs else ''}")
        return 0
    outcomes, problems = run_pages(pages, devel=arguments.devel, jobs=arguments.jobs, only=arguments.only,
                                   keep=arguments.keep)
    for problem in problems:
        print(f"doc_commands: PAGE   {problem}")
    for outcome in outcomes:
        if outcome.status == "marked":
            print(f"doc_commands: MARKED {outcome.block.ident} ({outcome.block.where}): {outcome.detail}")
    print(summary_line(outcomes))
    if arguments.junit:
        write_junit(arguments.junit, outcomes, problems)
    c = counts(outcomes)
    too_many = not arguments.only and c["marked share"] > MAX_MARKED_SHARE
    if too_many:
        print(f"doc_commands: {c['marked']} of {c['command blocks']} command blocks are marked: make some runnable")
    return 1 if c["failed"] or problems or too_many else 0


if __name__ == "__main__":
    sys.exit(main())
