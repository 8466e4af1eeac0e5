"""The doc test (checks/doc_commands.py): every fenced command block of README.md and docs/*.md
runs green against the built workspace, or carries a marker saying why not and what CI runs
instead; at most 15 % are marked; no block is unlabelled. One case per command block (a marked
block passes and says so), one for the pages' own problems, one for the share of marked blocks,
and one that runs a fixture page of deliberately broken commands and requires each to fail.

Run by scripts/run_tests.sh (catkin's run_tests: pytest-test_doc_commands.xml), or after
`source .ws/devel/setup.bash`: python3 -m pytest test/python/test_doc_commands.py [-k NAME].
BIRKHOFF_CART_DEVEL names another built devel space (the mutation check's scratch build).
BIRKHOFF_CART_DOC_BLOCKS=figures keeps only the blocks that show figures and the ROS-free blocks
above them (doc_commands.figure_blocks): CI runs those again as another CPU (CMakeLists.txt).
"""
import os
import pathlib
import sys

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "checks"))

import doc_commands  # noqa: E402

DEVEL = pathlib.Path(os.environ.get("BIRKHOFF_CART_DEVEL", REPO / ".ws" / "devel"))
FIXTURE = pathlib.Path(__file__).resolve().parent / "doc_fixtures" / "broken_commands.md"
BLOCKS = [block for page in doc_commands.default_pages(REPO) for block in doc_commands.blocks_of(page, REPO)]
COMMAND_BLOCKS = [block for block in BLOCKS if block.runs]
if os.environ.get("BIRKHOFF_CART_DOC_BLOCKS") == "figures":
    COMMAND_BLOCKS = doc_commands.figure_blocks(COMMAND_BLOCKS)


@pytest.fixture(scope="module")
def outcomes(request):
    """The outcome of every selected command block (pytest -k selects), run once, pages in parallel."""
    selected = {item.callspec.params["block"].ident for item in request.session.items
                if hasattr(item, "callspec") and "block" in item.callspec.params}
    results, _ = doc_commands.run_pages(doc_commands.default_pages(REPO), root=REPO, devel=DEVEL, jobs=2,
                                        only=selected or None, progress=lambda line: print(line, flush=True))
    return {outcome.block.ident: outcome for outcome in results}


@pytest.mark.parametrize("block", COMMAND_BLOCKS, ids=[block.ident for block in COMMAND_BLOCKS])
def test_the_block_runs_green_or_says_why_not(block, outcomes):
    outcome = outcomes[block.ident]
    if outcome.status == "marked":
        print(f"{block.where}: not run by the doc test: {block.marker}")
        return
    assert outcome.status == "passed", f"{block.where} ({block.ident}):\n{outcome.detail}"


def test_every_block_is_labelled_and_every_marker_names_what_ci_runs_instead():
    problems = []
    for block in BLOCKS:
        if not block.language:
            problems.append(f"{block.where}: no language")
        problem = doc_commands.marker_problem(block, REPO)
        if problem:
            problems.append(problem)
    assert not problems, "\n".join(problems)


def test_at_most_15_percent_of_the_command_blocks_are_marked():
    marked = [block for block in COMMAND_BLOCKS if block.marker]
    share = len(marked) / len(COMMAND_BLOCKS)
    print(f"{len(COMMAND_BLOCKS)} command blocks, {len(COMMAND_BLOCKS) - len(marked)} run, {len(marked)} marked "
          f"({100 * share:.1f} %):")
    for block in marked:
        print(f"  {block.where}: {block.marker}")
    assert len(COMMAND_BLOCKS) >= 20, "the pages' command blocks were not found"
    assert share <= doc_commands.MAX_MARKED_SHARE


def test_a_page_of_broken_commands_fails_block_by_block():
    results, problems = doc_commands.run_pages([FIXTURE], root=REPO, devel=DEVEL, jobs=1,
                                               progress=lambda line: print(line, flush=True))
    by_heading = {}
    text = FIXTURE.read_text().split("\n")
    for outcome in results:
        heading = next(line for line in reversed(text[:outcome.block.line]) if line.startswith("## "))
        by_heading[heading[3:]] = outcome
    expected = {
        "Passes": "passed",
        "Fails: a command that exits non-zero": "failed",
        "Fails: output the command does not print": "failed",
        "Fails: a topic nobody publishes": "failed",
        "Fails: a node that dies under a running roslaunch": "failed",
        "Fails: a Python example that raises": "failed",
        "Marked": "marked",
        "A page problem: a block without a language": "shown",
    }
    for heading, status in expected.items():
        assert by_heading[heading].status == status, f"{heading}: {by_heading[heading]}"
    assert "exited 3" in by_heading["Fails: a command that exits non-zero"].detail
    assert "not a whole number of steps" in by_heading["Fails: a command that exits non-zero"].detail
    assert "accuracy: ERROR" in by_heading["Fails: output the command does not print"].detail
    assert "showed no message" in by_heading["Fails: a topic nobody publishes"].detail
    assert "no_such_scene" in by_heading["Fails: a Python example that raises"].detail
    assert any("without a language" in problem for problem in problems), problems
    assert any("names no existing test or file" in problem for problem in problems), problems
    counts = doc_commands.counts(results)
    assert (counts["failed"], counts["marked"]) == (5, 2), counts  # the malformed marker's block is not run either
