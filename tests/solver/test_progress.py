"""The progress line of long runs (``solver/sweep/progress.py``): "k of N", the time left
and how many lines a stage writes on a terminal and in a log."""

from __future__ import annotations

import io

from gearsym.solver.sweep.progress import Progress, Stages, fmt_seconds


class _Clock:
    """A clock the test moves by hand (seconds)."""

    def __init__(self):
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_log_gets_at_most_one_line_per_tenth_and_the_last():
    log, clock = io.StringIO(), _Clock()
    bar = Progress(200, "sweeps", stream=log, clock=clock)
    for _ in range(200):
        clock.now += 1.0
        bar.step()
    lines = log.getvalue().splitlines()
    # one line at the first item and one as each tenth is entered (10 of them, the last
    # at 200 of 200): 11 lines for 200 items
    assert len(lines) == 11
    assert lines[0] == "sweeps: 1 of 200, 1 s"
    assert lines[-1] == "sweeps: 200 of 200, 3 min 20 s"


def test_the_time_left_comes_from_the_pace_after_the_first_item():
    log, clock = io.StringIO(), _Clock()
    bar = Progress(10, "maps", stream=log, clock=clock)
    clock.now += 60.0  # compiling before the first item: paid once
    bar.step()
    assert bar.left() is None  # one report says nothing of the pace
    clock.now += 2.0
    bar.step()
    # 2 s per item since the first, 8 items left: 16 s (the mean from the start, 31 s per
    # item, would say 248 s)
    assert bar.left() == 16.0
    assert "2 of 10, 1 min 02 s, about 16 s left" in log.getvalue().splitlines()[-1]


def test_a_terminal_line_is_redrawn_in_place_and_ended_once():
    term, clock = _Terminal(), _Clock()
    bar = Progress(3, "figures", stream=term, clock=clock)
    for _ in range(3):
        clock.now += 1.0
        bar.step()
    bar.finish()  # already at its end: nothing more
    text = term.getvalue()
    assert text.count("\r") == 3 and text.count("\n") == 1 and text.endswith("\n")
    assert "figures: 3 of 3, 3 s" in text


def test_stages_are_numbered_timed_and_a_short_stage_is_ended():
    log = io.StringIO()
    stages = Stages(2, "reproduce", stream=log)
    stages.stage("sweeps (points)", 4).step(n=4)
    stages.stage("report (sections)", 5).step()  # ended below with items uncounted
    stages.end()
    lines = log.getvalue().splitlines()
    assert lines[0].startswith("reproduce 1 of 2, sweeps (points): 4 of 4")
    assert lines[-1].startswith("reproduce 2 of 2, report (sections): 5 of 5")
    assert [name for name, _ in stages.times] == ["sweeps (points)", "report (sections)"]


def test_disabled_counts_and_writes_nothing():
    log = io.StringIO()
    bar = Progress(5, "x", stream=log, enabled=False)
    bar.step(n=2)
    bar.finish()
    assert bar.done == 2 and log.getvalue() == ""


def test_seconds_read_as_minutes_past_one():
    assert fmt_seconds(59.4) == "59 s" and fmt_seconds(125) == "2 min 05 s"


def test_what_a_stage_still_does_after_its_items_is_said_with_the_last():
    log = io.StringIO()
    bar = Progress(2, "sweeps", stream=log, after="now the border runs, re-examined")
    bar.step("lambda=0")
    bar.step("lambda=1")
    first, last = log.getvalue().splitlines()
    assert first.endswith("lambda=0") and "border" not in first
    assert last.endswith("lambda=1; now the border runs, re-examined")
