"""A target in user units is a float in native units: 8.88 mm at 0.01 mm per step is
887.9999999999999 steps, which a stepper kind sends as step 888.  Arriving there is
arriving at the target -- found when the CA face (issue 26) made an interrupted move a
failed one: the PMC007 (in-position window 0) judged moves that stood on their target
as "stopped by a stop from another program"."""
import pytest

from motorbus import Bench
from motorbus.pytest_plugin import default_bench


def test_a_target_whose_native_value_is_not_a_whole_step_is_arrived_at():
    data = default_bench()
    data["axis"] = {k: v for k, v in data["axis"].items() if v["kind"] == "pmc007"}
    for v in data["axis"].values():
        v["units"] = {"name": "mm", "scale": 0.01}
    with Bench.from_dict(data, sim=True) as bench:
        axis = next(iter(bench.axes.values()))
        axis.enable()
        for target in (8.88, 1.15, 0.29):             # 888.0000000000001, 114.99999999999999, 28.999999999999996
            assert target / 0.01 != round(target / 0.01)
            axis.move_to(target)                       # raised MoveInterrupted before the fix
            assert axis.status.last_move.state == "done"
            assert axis.position == pytest.approx(target, abs=1e-9)   # step 115 * 0.01 mm
