"""Motion benchmark against ruckig (PyPI) in the same run.

    PYTHONPATH=python python3 bench/motion.py [N]

Per-call times from Python include each binding's overhead (ruckig's
calculate() needs its InputParameter filled; ours takes MotionState/Limits),
so the "per call" ratio compares like with like.  "batch" is our planner in a
C++ loop (jerk_limited_durations), i.e. the C++ cost without Python; ruckig's
C++ cost is quoted from the issue's anchors (0.36 us/plan, 6 ns/sample).
Timing is CPU time of this process (time.process_time_ns): the 2-core VM is
shared, so wall time would mostly measure the scheduler.
"""
import sys
import time

import numpy as np
import ruckig

from motorbus import motion


def cases(n, seed):
    rng = np.random.default_rng(seed)
    vmax = rng.uniform(0.05, 20, n)
    amax = rng.uniform(0.05, 20, n)
    jmax = rng.uniform(0.05, 200, n)
    p0 = rng.uniform(-100, 100, n)
    pt = p0 + rng.choice([-1, 1], n) * 10 ** rng.uniform(-4, 2, n)
    v0 = np.where(np.arange(n) % 2 == 0, 0.0, rng.uniform(-1, 1, n) * vmax)
    return np.column_stack([p0, v0, np.zeros(n), pt, vmax, amax, jmax])


def per_call(fn, items):
    t0 = time.process_time_ns()
    for it in items:
        fn(it)
    return (time.process_time_ns() - t0) / len(items)


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
    c = cases(n, 1)
    otg = ruckig.Ruckig(1)
    traj = ruckig.Trajectory(1)
    inputs = []
    for p0, v0, a0, pt, vm, am, jm in c:
        inp = ruckig.InputParameter(1)
        inp.current_position = [p0]
        inp.current_velocity = [v0]
        inp.current_acceleration = [a0]
        inp.target_position = [pt]
        inp.max_velocity = [vm]
        inp.max_acceleration = [am]
        inp.max_jerk = [jm]
        inputs.append(inp)
    ours_in = [(motion.MotionState(r[0], r[1], 0.0), r[3], motion.Limits(r[4], r[5], 0.0, r[6])) for r in c]

    rk = min(per_call(lambda i: otg.calculate(i, traj), inputs) for _ in range(3))
    us = min(per_call(lambda a: motion.plan_jerk_limited(*a), ours_in) for _ in range(3))
    t0 = time.process_time_ns()
    for _ in range(5):
        motion.jerk_limited_durations(c)
    batch = (time.process_time_ns() - t0) / (5 * n)
    # Per-call binding overhead, measured with a request that needs no planning
    # (already at rest on the target) on both sides.
    idle = ruckig.InputParameter(1)
    idle.current_position = [1.0]
    idle.target_position = [1.0]
    idle.max_velocity = [1.0]
    idle.max_acceleration = [1.0]
    idle.max_jerk = [1.0]
    rk_idle = min(per_call(lambda i: otg.calculate(i, traj), [idle] * n) for _ in range(3))
    ours_idle_args = (motion.MotionState(1.0, 0.0, 0.0), 1.0, motion.Limits(1.0, 1.0, 0.0, 1.0))
    us_idle = min(per_call(lambda a: motion.plan_jerk_limited(*a), [ours_idle_args] * n) for _ in range(3))
    print(f"jerk-limited 1-DoF plan, {n} random cases (half from rest, half moving):")
    print(f"  overhead (call that plans nothing): ruckig {rk_idle:.1f} ns, motorbus {us_idle:.1f} ns")
    print(f"  ruckig per call from Python      {rk:9.1f} ns")
    print(f"  motorbus per call from Python    {us:9.1f} ns   ratio ruckig/motorbus = {rk / us:.2f}")
    print(f"  motorbus in a C++ loop (batch)   {batch:9.1f} ns   vs ruckig C++ anchor 360 ns: {360 / batch:.2f}x")
    print(f"  minus each side's overhead: ruckig {rk - rk_idle:.1f} ns, motorbus {us - us_idle:.1f} ns, "
          f"ratio {(rk - rk_idle) / (us - us_idle):.2f}")

    # Trapezoidal: ruckig with infinite jerk vs our trapezoid.
    for inp in inputs:
        inp.max_jerk = [float("inf")]
    rk_t = min(per_call(lambda i: otg.calculate(i, traj), inputs) for _ in range(3))
    tr_in = [(motion.MotionState(r[0], r[1], 0.0), r[3], motion.Limits(r[4], r[5])) for r in c]
    us_t = min(per_call(lambda a: motion.plan_trapezoid(*a), tr_in) for _ in range(3))
    print("trapezoidal 1-DoF plan:")
    print(f"  ruckig (max_jerk=inf) per call   {rk_t:9.1f} ns")
    print(f"  motorbus per call from Python    {us_t:9.1f} ns   ratio = {rk_t / us_t:.2f}")

    # Sampling one trajectory.
    inp = inputs[1]
    inp.max_jerk = [50.0]
    otg.calculate(inp, traj)
    prof = motion.plan_jerk_limited(*ours_in[1][:2], motion.Limits(c[1, 4], c[1, 5], 0.0, 50.0))
    ts = np.random.default_rng(2).uniform(0, traj.duration, 20000)
    rk_s = min(per_call(traj.at_time, ts) for _ in range(3))
    us_s = min(per_call(prof.at, ts) for _ in range(3))
    t0 = time.process_time_ns()
    prof.sample(1_000_000)
    vec = (time.process_time_ns() - t0) / 1_000_000
    print("sampling (p, v, a at t):")
    print(f"  ruckig at_time per call          {rk_s:9.1f} ns")
    print(f"  motorbus at per call             {us_s:9.1f} ns   ratio = {rk_s / us_s:.2f}")
    print(f"  motorbus sample(1e6) -> numpy    {vec:9.2f} ns/sample (ruckig C++ anchor 6 ns)")

    # 3-DoF time-synchronised, from rest.
    rng = np.random.default_rng(3)
    m3 = 5000
    rows = []
    inputs3 = []
    for _ in range(m3):
        row = []
        for _k in range(3):
            p0 = rng.uniform(-50, 50)
            row += [p0, p0 + rng.uniform(-50, 50), rng.uniform(0.1, 10), rng.uniform(0.1, 10), rng.uniform(0.1, 100)]
        rows.append(row)
        r = np.array(row).reshape(3, 5)
        inp = ruckig.InputParameter(3)
        inp.current_position = r[:, 0].tolist()
        inp.target_position = r[:, 1].tolist()
        inp.max_velocity = r[:, 2].tolist()
        inp.max_acceleration = r[:, 3].tolist()
        inp.max_jerk = r[:, 4].tolist()
        inputs3.append(inp)
    otg3 = ruckig.Ruckig(3)
    traj3 = ruckig.Trajectory(3)
    rk3 = min(per_call(lambda i: otg3.calculate(i, traj3), inputs3) for _ in range(3))
    c3 = np.array(rows)
    t0 = time.process_time_ns()
    for _ in range(3):
        motion.synchronized_jerk_limited_durations(c3)
    us3 = (time.process_time_ns() - t0) / (3 * m3)
    print("3-DoF jerk-limited time-synchronised plan (from rest):")
    print(f"  ruckig per call from Python      {rk3:9.1f} ns")
    print(f"  motorbus in a C++ loop (batch)   {us3:9.1f} ns   ratio = {rk3 / us3:.2f} (ruckig C++ anchor 2370 ns)")

    # Integer step times (ruckig has none).
    p = motion.plan(1_000_000, max_velocity=50000, max_acceleration=200000, max_jerk=2e6)
    t0 = time.process_time_ns()
    t, d = p.step_times()
    st = (time.process_time_ns() - t0) / len(t)
    print(f"integer step times: {len(t)} steps, {st:.2f} ns/step incl. numpy copy (target <= 10 ns; Klipper ~20 ns)")


if __name__ == "__main__":
    main()
