"""lang/collector.py: the collector is off while a program compiles, and as it was afterwards."""

from __future__ import annotations

import gc
import weakref

from liganimate.lang import collector


def test_the_collector_is_off_inside_and_restored_after_even_on_error():
    assert gc.isenabled()
    try:
        with collector.paused():
            assert not gc.isenabled()
            with collector.paused():  # a library loaded while a program compiles
                assert not gc.isenabled()
            assert not gc.isenabled()
            raise KeyError("boom")
    except KeyError:
        pass
    assert gc.isenabled()


def test_a_disabled_collector_stays_disabled():
    gc.disable()
    try:
        with collector.paused():
            pass
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_survivors_are_frozen_and_a_cycle_among_them_is_collected_once_unfrozen(monkeypatch):
    class Node:
        pass

    monkeypatch.setattr(collector, "_freezing", False)
    collector.freeze_survivors()  # as the command line does
    with collector.paused():
        a, b = Node(), Node()
        a.other, b.other = b, a
        ref = weakref.ref(a)
    assert gc.get_freeze_count() > 0
    del a, b  # cyclic garbage among frozen objects
    gc.collect()
    assert ref() is not None  # frozen: the collector leaves it alone
    with collector.paused():
        assert gc.get_freeze_count() == 0  # the next compile unfreezes on entry
    gc.unfreeze()
    gc.collect()
    assert ref() is None


def test_a_library_user_s_process_is_never_frozen(monkeypatch):
    # liganimate.load in a notebook: the user's objects must stay collectable.
    import liganimate

    monkeypatch.setattr(collector, "_freezing", False)
    gc.unfreeze()
    was_on = gc.isenabled()
    liganimate.loads("      X = 1\n")
    assert gc.get_freeze_count() == 0 and gc.isenabled() == was_on
