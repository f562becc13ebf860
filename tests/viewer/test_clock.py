import pytest

from deforma.viewer.clock import FixedStepClock


def test_same_steps_at_any_frame_rate():
    # one simulated second at 600 Hz, shown at 24, 60 and 144 frames/s: 600 steps each time
    dt = 1 / 600
    for fps in (24, 60, 144):
        c = FixedStepClock()
        assert sum(c.advance(1 / fps, dt=dt) for _ in range(fps)) == 600


def test_slow_frame_is_capped_not_caught_up():
    c = FixedStepClock(max_frame_time=0.1)
    assert c.advance(3.0, dt=0.01) == 10
    assert c.dropped == pytest.approx(2.9)
    assert c.advance(0.01, dt=0.01) == 1  # no backlog carried into the next frame


def test_max_steps_caps_tiny_dt():
    c = FixedStepClock(max_frame_time=0.1, max_steps=50)
    assert c.advance(0.1, dt=1e-4) == 50
    assert c.accumulator == 0.0


def test_remainder_carries_over_and_reset_forgets_it():
    c = FixedStepClock()
    assert c.advance(0.015, dt=0.01) == 1
    assert c.advance(0.006, dt=0.01) == 1  # 0.005 left over + 0.006
    c.advance(0.005, dt=0.01)
    c.reset()
    assert c.advance(0.005, dt=0.01) == 0


@pytest.mark.parametrize("kwargs", [{"max_frame_time": 0}, {"max_frame_time": float("nan")}, {"max_steps": 0}])
def test_bad_settings_refused(kwargs):
    with pytest.raises(ValueError):
        FixedStepClock(**kwargs)
