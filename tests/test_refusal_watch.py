# SPDX-License-Identifier: GPL-2.0-or-later
"""addon/hbao/refusal_watch.py without Blender: when a refusal of Python's
writes counts as the kind that does not end, and that it is told once.
tests/test_faults_ui.py holds writes.py to it in a Blender left stuck."""
import pytest

from conftest import REPO  # noqa: F401  (puts the add-on on sys.path)
from hbao import refusal_watch
from hbao.refusal_watch import ASKED_WITHIN_S, STUCK_AFTER_S, RefusalWatch


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def asks(watch, clock, seconds, every=0.25, allowed=False, job_running=False):
    """The answers of asks every `every` s for `seconds`, the first at once."""
    told = []
    for k in range(int(round(seconds / every)) + 1):
        clock.now += every if k else 0.0
        answer = watch.note(allowed, job_running)
        if answer is not None:
            told.append((clock.now, answer))
    return told


def test_refused_at_every_ask_is_told_once_after_the_limit():
    clock = Clock()
    watch = RefusalWatch(clock)
    start = clock.now
    told = asks(watch, clock, 3 * STUCK_AFTER_S)
    assert len(told) == 1, told
    at, lasted = told[0]
    assert lasted == pytest.approx(STUCK_AFTER_S) and at - start == pytest.approx(STUCK_AFTER_S)
    assert watch.told and watch.lasted == lasted


def test_not_before_the_limit():
    clock = Clock()
    watch = RefusalWatch(clock)
    assert asks(watch, clock, STUCK_AFTER_S - 0.25) == []
    assert not watch.told


def test_a_running_job_starts_the_count_again():
    clock = Clock()
    watch = RefusalWatch(clock)
    assert asks(watch, clock, STUCK_AFTER_S - 1.0) == []
    assert asks(watch, clock, 10.0, job_running=True) == []  # a render: refusals are real
    assert asks(watch, clock, STUCK_AFTER_S - 1.0) == []
    assert len(asks(watch, clock, 2.0)) == 1


@pytest.mark.parametrize("gap", [ASKED_WITHIN_S + 0.5, 60.0])
def test_asks_further_apart_than_the_limit_are_not_one_refusal(gap):
    clock = Clock()
    watch = RefusalWatch(clock)
    for _ in range(5):
        assert asks(watch, clock, 1.0) == []
        clock.now += gap
    assert not watch.told


def test_a_slow_pass_within_the_limit_keeps_the_count():
    clock = Clock()
    watch = RefusalWatch(clock)
    start = clock.now
    assert asks(watch, clock, 1.0) == []
    clock.now += ASKED_WITHIN_S - 0.5  # (one slow pass of the main loop)
    told = asks(watch, clock, STUCK_AFTER_S)
    expected = max(STUCK_AFTER_S, 1.0 + ASKED_WITHIN_S - 0.5)
    assert told and told[0][0] - start == pytest.approx(expected), told


def test_an_allowed_write_ends_it_and_a_later_one_is_told_again():
    clock = Clock()
    watch = RefusalWatch(clock)
    assert len(asks(watch, clock, STUCK_AFTER_S)) == 1
    assert watch.note(True, False) is None and not watch.told and watch.lasted is None
    assert len(asks(watch, clock, STUCK_AFTER_S)) == 1


def test_reset_forgets_everything():
    clock = Clock()
    watch = RefusalWatch(clock)
    assert len(asks(watch, clock, STUCK_AFTER_S)) == 1
    watch.reset()
    assert not watch.told
    assert asks(watch, clock, STUCK_AFTER_S - 0.25) == []


def test_the_sentences_say_what_to_do():
    sentences = refusal_watch.stuck_sentences(5.2)
    assert sentences[0].startswith("Blender has refused every change from Python for 5 s")
    assert "Save the file and restart Blender." in sentences
    assert all(sentence.endswith(".") and len(sentence) <= 100 for sentence in sentences)
