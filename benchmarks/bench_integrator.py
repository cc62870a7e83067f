"""Work-precision diagrams of the splitting integrator against scipy's DOP853, in one run.

    python benchmarks/bench_integrator.py [--plot docs/img/work-precision.png] [--repeat 5] [--clock cpu|wall]
                                          [--cases abc]

Error against time (best of ``--repeat`` interleaved rounds) for a sweep of fixed steps (splitting) and
of tolerances (DOP853, rtol = atol; the splitting's own step control, rtol = atol), on three cases, 201
outputs each (the splitting's steps divide the output interval: k = 1, 2, 3, ... steps per output):

(a) Heavy symmetric top on a pivot (Chapter 4, "Rigid Body Motion", §4.4.3): I1 = I2 = 0.02, I3 = 0.005 kg·m²
    about the pivot, M = 0.5 kg, l = 0.04 m, g = 9.80665 m/s², released at rest at θ0 = 0.6 rad with spin
    ω3 = 30 rad/s (large cusped nutation), 10 nutation periods.  Torque τ_body = −M g l e3 × ẑ_body.
    Error: max |cos θ(t) − u(t)| with u(t) the exact solution through Weierstrass' ℘ (exercise 4.10,
    ``dynamics.top_motion.top_cos_theta``).  Also printed: the full-state error against DOP853 at
    rtol 3e-14 / atol 1e-16, itself checked against ℘.
(b) Torque-free asymmetric body I = (1, 2, 3), ω0 = (0.1, 1, 0.05) (near the intermediate axis, Dzhanibekov
    flips), t ≤ 100 s.  Reference: the closed form ``dynamics.torque_free.torque_free_motion``.  The splitting
    then is the exact free flow (its error does not depend on the step); the closed form evaluated at the
    outputs (``simulate`` default) is shown as one point.
(c) Gravity gradient τ = 3 n² ẑ_b × (I ẑ_b), n = 0.5 rad/s, same body and ω0, t ≤ 100 s: a strong torque
    (its time scale 1/(n√3) ≈ 1.2 s is shorter than the spin period).  Reference: DOP853 at rtol 3e-14 /
    atol 1e-16, cross-checked by the splitting at h = 1/64 s.

Error (b, c): max over the outputs of max(|ω − ω_ref| / max|ω_ref|, |R − R_ref|) (R the rotation matrix).

Both integrators call the same torque, written on Python floats (``q.tolist()``), and DOP853 gets the
package's float-level right-hand side (``dynamics.integrate._make_rhs``, its fastest form).  The ratio "at
matched accuracy" is the splitting's time interpolated (log-log, along the lower envelope of its curve) at
the error DOP853 reaches at each tolerance, divided by DOP853's time there.  The splitting is timed on the C
kernel (``_accel.split_steps``) and on the pure-Python path (``INERTIA_TOOL_NO_ACCEL=1``).  Absolute times
drift on a shared machine; ratios come from one run.

Clock: ``--clock cpu`` (default) times the process's CPU time, which equals the wall time of these
single-threaded runs on an idle machine but, unlike the wall time on a machine shared with other jobs, does not
count the waits for a free core; ``--clock wall`` times the wall clock (``time.perf_counter``).
"""

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import inertia_tool as it  # noqa: E402
from inertia_tool._native import NO_ACCEL_ENV, accel  # noqa: E402
from inertia_tool.dynamics.integrate import _make_rhs  # noqa: E402
from inertia_tool.dynamics.splitting import integrate_splitting  # noqa: E402
from inertia_tool.dynamics.top import heavy_top  # noqa: E402
from inertia_tool.dynamics.top_motion import top_cos_theta  # noqa: E402
from inertia_tool.dynamics.torque_free import torque_free_motion  # noqa: E402
from inertia_tool.dynamics.trajectory import resolve_body  # noqa: E402
from inertia_tool.rotations import quaternion_to_matrix  # noqa: E402

DOP_TOLERANCES = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13)
CONTROL_TOLERANCES = (1e-8, 1e-10, 1e-12, 1e-14)
MIN_SAMPLE = 0.03        # s: shorter runs are repeated within a round and averaged


CLOCKS = {"cpu": time.process_time, "wall": time.perf_counter}
clock = CLOCKS["cpu"]                                        # set by --clock
CLOCK_NAME = "CPU"


def best_time(fn, repeat):
    best, out = math.inf, None
    for _ in range(repeat):
        start = clock()
        out = fn()
        best = min(best, clock() - start)
    return best, out


class python_path:
    """Context: the pure-Python path of the splitting (the C extension switched off)."""

    def __enter__(self):
        self.saved = os.environ.get(NO_ACCEL_ENV)
        os.environ[NO_ACCEL_ENV] = "1"

    def __exit__(self, *exc):
        if self.saved is None:
            del os.environ[NO_ACCEL_ENV]
        else:
            os.environ[NO_ACCEL_ENV] = self.saved


def state_error(w, q, w_ref, q_ref):
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    rel_w = np.max(np.abs(w - w_ref)) / np.max(np.abs(w_ref))
    return max(rel_w, np.max(np.abs(quaternion_to_matrix(q) - quaternion_to_matrix(q_ref))))


def time_at(points, error):
    """Time to reach ``error`` along the lower envelope of (error, time) points, log-log interpolated; the
    cheapest point's time when every point is more accurate; None when no point reaches it."""
    envelope = []
    for e, t in sorted(points, key=lambda p: p[1]):        # by time: keep each point more accurate than all
        if not envelope or e < envelope[-1][0]:             # faster ones
            envelope.append((e, t))
    if error >= envelope[0][0]:
        return envelope[0][1]
    for (e0, t0), (e1, t1) in zip(envelope[:-1], envelope[1:]):
        if e1 <= error <= e0:
            f = math.log(error / e0) / math.log(e1 / e0) if e1 < e0 else 1.0
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None


def run_case(name, body, w0, q0, t, torque, error_of, steps, repeat, python_steps):
    """Sweep DOP853 tolerances and splitting steps; returns {curve label: [(error, time, detail)]}.

    Timing: ``repeat`` rounds over all runs (interleaved, so that a burst of load on the shared machine hits
    every curve alike), the best time of each run kept; after the first round a run shorter than
    ``MIN_SAMPLE`` is repeated within the round and its mean taken; the slow pure-Python runs go in the first
    three rounds only."""
    principal = resolve_body(body)
    tensor = principal.axes @ np.diag(principal.moments) @ principal.axes.T
    rhs = _make_rhs(tensor, torque)
    y0 = np.concatenate([w0, q0])
    jobs = []                                                # (label, detail, run -> (w, q, detail), rounds)

    def dop(tol):
        sol = solve_ivp(rhs, (t[0], t[-1]), y0, method="DOP853", rtol=tol, atol=tol, t_eval=t)
        return sol.y[:3].T, sol.y[3:].T, f"tol {tol:.0e}, {sol.nfev} calls"

    def split(step=None, tol=1e-12):
        w, q, n = integrate_splitting(principal.moments, principal.axes, w0, q0, t, torque, step=step, rtol=tol,
                                      atol=tol)
        return w, q, (f"h {step:.4g} s" if step else f"tol {tol:.0e}") + f", {n} steps"

    def python_split(step):
        with python_path():
            return split(step)

    jobs += [("DOP853", lambda tol=tol: dop(tol), repeat) for tol in DOP_TOLERANCES]
    jobs += [("splitting (C), fixed step", lambda h=h: split(step=h), repeat) for h in steps]
    jobs += [("splitting (Python), fixed step", lambda h=h: python_split(h), min(repeat, 3))
             for h in steps[:python_steps]]
    jobs += [("splitting (C), step control", lambda tol=tol: split(tol=tol), repeat) for tol in CONTROL_TOLERANCES]
    best = [math.inf] * len(jobs)
    outputs = [None] * len(jobs)
    inner = [1] * len(jobs)
    for round_ in range(repeat):
        for index, (_label, run, rounds) in enumerate(jobs):
            if round_ >= rounds:
                continue
            start = clock()
            for _ in range(inner[index]):
                outputs[index] = run()
            seconds = (clock() - start) / inner[index]
            best[index] = min(best[index], seconds)
            inner[index] = max(1, min(50, int(MIN_SAMPLE / max(seconds, 1e-6))))   # short runs: average several
    curves = {}
    print(f"\n{name}")
    for (label, _, _), seconds, (w, q, detail) in zip(jobs, best, outputs):
        error = error_of(w, q)
        curves.setdefault(label, []).append((error, seconds, detail))
        print(f"  {label:32s} {detail:28s} error {error:9.2e}  time {seconds * 1e3:8.2f} ms")
    return curves


def print_ratios(curves, label="splitting (C), fixed step"):
    """The splitting's time at each DOP853 accuracy, as a ratio; returns the ratio at DOP853's 1e-12."""
    print(f"  ratio {label} / DOP853 at matched accuracy:")
    headline = None
    for (e, s, detail), tol in zip(curves["DOP853"], DOP_TOLERANCES):
        ours = time_at([(p[0], p[1]) for p in curves[label]], e)
        text = "not reached" if ours is None else f"{ours / s:6.3f}"
        print(f"    DOP853 {detail:26s} error {e:9.2e}: {text}")
        if tol == 1e-12 and ours is not None:
            headline = ours / s
    return headline


def heavy_top_case(repeat):
    i1, i3, mass, length, g, theta0, omega3 = 0.02, 0.005, 0.5, 0.04, 9.80665, 0.6, 30.0
    top = heavy_top(i1, i3, mass, length, theta0=theta0, omega3=omega3, g=g)
    mgl = mass * g * length
    period = top.nutation_period
    t = np.linspace(0.0, 10.0 * period, 201)
    u_exact = top_cos_theta(top, t + 0.5 * period)          # released at rest: θ0 = θ_min, half a period on

    def torque(_t, q, _w):                                   # −M g l e3 × ẑ_body, ẑ_body = third row of R(q)
        qw, qx, qy, qz = q.tolist()
        return (2.0 * mgl * (qy * qz + qw * qx), -2.0 * mgl * (qx * qz - qw * qy), 0.0)

    w0 = np.array([0.0, 0.0, omega3])
    q0 = np.array([math.cos(0.5 * theta0), 0.0, math.sin(0.5 * theta0), 0.0])
    tensor = np.diag([i1, i1, i3])
    ref = solve_ivp(_make_rhs(tensor, torque), (0.0, t[-1]), np.concatenate([w0, q0]), method="DOP853",
                    rtol=3e-14, atol=1e-16, t_eval=t).y.T

    def u_error(w, q):
        q = q / np.linalg.norm(q, axis=1, keepdims=True)
        return np.max(np.abs(1.0 - 2.0 * (q[:, 1] ** 2 + q[:, 2] ** 2) - u_exact))

    print(f"heavy top: nutation period {period:.4f} s, θ {top.theta_min:.3f}..{top.theta_max:.3f} rad, "
          f"{top.precession_kind}; tight DOP853 reference: |cos θ − ℘ solution| = "
          f"{u_error(ref[:, :3], ref[:, 3:]):.1e}")
    steps = tuple((t[1] - t[0]) / k for k in (1, 2, 3, 4, 6, 8))
    curves = run_case("(a) heavy top, error in cos θ against the Weierstrass ℘ solution", tensor, w0, q0, t,
                      torque, u_error, steps, repeat, python_steps=4)
    ratio = (print_ratios(curves), print_ratios(curves, "splitting (Python), fixed step"))
    full = run_case("(a') heavy top, full-state error against DOP853 3e-14", tensor, w0, q0, t, torque,
                    lambda w, q: state_error(w, q, ref[:, :3], ref[:, 3:]), steps[:4], repeat, python_steps=0)
    print_ratios(full)
    return curves, ratio


def torque_free_case(repeat):
    moments, w0, q0 = np.array([1.0, 2.0, 3.0]), np.array([0.1, 1.0, 0.05]), np.array([1.0, 0.0, 0.0, 0.0])
    t = np.linspace(0.0, 100.0, 201)
    w_ref, q_ref, _ = torque_free_motion(moments, w0, t)

    def error_of(w, q):
        return state_error(w, q, w_ref, q_ref)

    steps = (0.5, 0.25, 0.125)                               # one, two and four steps per output
    curves = run_case("(b) torque-free asymmetric body against the closed form", moments, w0, q0, t, None,
                      error_of, steps, repeat, python_steps=2)
    seconds, traj = best_time(lambda: it.simulate(moments, w0, t), repeat)
    curves["closed form (simulate default)"] = [(error_of(traj.angular_velocity, traj.orientation), seconds,
                                                 traj.method)]
    print(f"  closed form, simulate() ({traj.method}): error {curves['closed form (simulate default)'][0][0]:.2e}"
          f"  time {seconds * 1e3:.2f} ms")
    ratio = (print_ratios(curves), print_ratios(curves, "splitting (Python), fixed step"),
             print_ratios(curves, "closed form (simulate default)"))
    return curves, ratio


def gravity_gradient_case(repeat, rate=0.5):
    moments, w0, q0 = np.array([1.0, 2.0, 3.0]), np.array([0.1, 1.0, 0.05]), np.array([1.0, 0.0, 0.0, 0.0])
    k = 3.0 * rate ** 2
    i1, i2, i3 = moments.tolist()

    def torque(_t, q, _w):                                   # 3 n² ẑ_b × (I ẑ_b)
        qw, qx, qy, qz = q.tolist()
        z0, z1, z2 = 2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)
        return (k * (i3 - i2) * z1 * z2, k * (i1 - i3) * z2 * z0, k * (i2 - i1) * z0 * z1)

    t = np.linspace(0.0, 100.0, 201)
    ref = solve_ivp(_make_rhs(np.diag(moments), torque), (0.0, 100.0), np.concatenate([w0, q0]),
                    method="DOP853", rtol=3e-14, atol=1e-16, t_eval=t).y.T
    w_chk, q_chk, _ = integrate_splitting(moments, np.eye(3), w0, q0, t, torque, step=1.0 / 64)
    agreement = state_error(w_chk, q_chk, ref[:, :3], ref[:, 3:])
    print(f"\ngravity gradient n = {rate} rad/s: reference DOP853 3e-14 and splitting h = 1/64 s agree to "
          f"{agreement:.1e} (errors below that are not resolved)")

    def error_of(w, q):
        return state_error(w, q, ref[:, :3], ref[:, 3:])

    steps = tuple(0.5 / k for k in (1, 2, 3, 4, 5, 6, 8))     # k steps per output interval
    curves = run_case(f"(c) gravity gradient n = {rate} rad/s against DOP853 3e-14", moments, w0, q0, t,
                      torque, error_of, steps, repeat, python_steps=5)
    ratio = (print_ratios(curves), print_ratios(curves, "splitting (Python), fixed step"))
    return curves, ratio, agreement


def stage_costs(repeat):
    """Where the time goes: µs per torque call of each integrator, split into its parts (one run)."""
    moments, w0, q0 = np.array([1.0, 2.0, 3.0]), np.array([0.1, 1.0, 0.05]), np.array([1.0, 0.0, 0.0, 0.0])
    t = np.linspace(0.0, 20.0, 41)
    k, (i1, i2, i3) = 0.75, (1.0, 2.0, 3.0)

    def gravity(_t, q, _w):
        qw, qx, qy, qz = q.tolist()
        z0, z1, z2 = 2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)
        return (k * (i3 - i2) * z1 * z2, k * (i1 - i3) * z2 * z0, k * (i2 - i1) * z0 * z1)

    def zero(_t, _q, _w):
        return (0.0, 0.0, 0.0)

    q_arg, w_arg = np.array([0.9, 0.1, -0.3, 0.2]), np.array([0.1, 1.0, 0.05])
    torque_alone, _ = best_time(lambda: [gravity(0.0, q_arg, w_arg) for _ in range(2000)], repeat)
    rows = [("the torque itself (floats, q.tolist())", torque_alone / 2000)]
    for label, torque in (("DOP853 call, no torque (rhs + scipy)", zero), ("DOP853 call, gravity gradient", gravity)):
        rhs = _make_rhs(np.diag(moments), torque)
        seconds, sol = best_time(lambda: solve_ivp(rhs, (0.0, 20.0), np.concatenate([w0, q0]), method="DOP853",
                                                   rtol=1e-12, atol=1e-12, t_eval=t), repeat)
        rows.append((label, seconds / sol.nfev))
    for body, kind in ((moments, "asymmetric"), (np.array([1.0, 1.0, 3.0]), "symmetric")):
        for path in ("C", "Python"):
            for label, torque in (("free flow only", None), ("+ call of a zero torque", zero),
                                  ("+ gravity gradient", gravity)):
                def run():
                    return integrate_splitting(body, np.eye(3), w0, q0, t, torque, step=0.1)
                if path == "Python":
                    with python_path():
                        seconds, (_, _, n) = best_time(run, repeat)
                else:
                    seconds, (_, _, n) = best_time(run, repeat)
                rows.append((f"splitting stage ({path}, {kind}): {label}", seconds / (11 * n)))
    dop = rows[2][1]
    print("\nwhere the time goes: µs per torque call (splitting: per stage = one exact free flow + one kick)")
    for label, seconds in rows:
        print(f"  {label:62s} {seconds * 1e6:7.2f} µs  {seconds / dop:6.2f} × DOP853's")


STYLE = {"DOP853": dict(color="black", marker="s"),
         "splitting (C), fixed step": dict(color="tab:blue", marker="o"),
         "splitting (Python), fixed step": dict(color="tab:blue", marker="o", linestyle="--", mfc="none"),
         "splitting (C), step control": dict(color="tab:orange", marker="^"),
         "closed form (simulate default)": dict(color="tab:green", marker="*", markersize=12, linestyle="none")}


def plot(panels, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter
    fig, axes = plt.subplots(1, len(panels), figsize=(5.0 * len(panels), 4.9), constrained_layout=True)
    handles = {}
    for ax, (title, curves, ratio, floor) in zip(axes, panels):
        for label, points in curves.items():
            pts = sorted((p[1], p[0]) for p in points)
            (line,) = ax.loglog([p[0] * 1e3 for p in pts], [max(p[1], 1e-17) for p in pts], label=label,
                                **STYLE.get(label, {}))
            handles[label] = line
        if floor is not None:
            ax.axhline(floor, color="grey", linestyle=":", linewidth=1)
            ax.annotate("reference resolved to here", (ax.get_xlim()[0], floor), xytext=(4, -11),
                        textcoords="offset points", fontsize=7, color="grey")
        ax.set_xlabel(f"{CLOCK_NAME} time [ms], best of interleaved repeats")
        ax.set_ylabel("max error over the 201 outputs")
        note = "" if ratio is None else f"\nsplitting / DOP853 time at DOP853 (tol 1e-12)'s error: {ratio:.2f}"
        ax.set_title(title + note, fontsize=9)
        ax.grid(True, which="major", alpha=0.3)
        ax.xaxis.set_minor_formatter(NullFormatter())          # short time ranges: no crowded minor labels
    fig.legend(list(handles.values()), list(handles), loc="outside lower center", ncol=len(handles), fontsize=8)
    fig.savefig(path, dpi=110)
    print(f"\nwrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", help="write the work-precision diagram (PNG) here")
    parser.add_argument("--repeat", type=int, default=5, help="timing repeats (best is kept)")
    parser.add_argument("--clock", choices=sorted(CLOCKS), default="cpu",
                        help="cpu: the process's CPU time (default; robust on a shared machine); wall: wall clock")
    parser.add_argument("--cases", default="abc", help="which cases to run (letters of a, b, c); the plot needs all")
    args = parser.parse_args()
    global clock, CLOCK_NAME
    clock, CLOCK_NAME = CLOCKS[args.clock], {"cpu": "CPU", "wall": "wall"}[args.clock]
    print(f"inertia_tool {it.__version__}; C kernel: {'yes' if accel() is not None else 'NO (Python path only)'}; "
          f"clock: {args.clock}")
    stage_costs(args.repeat)
    none = ({}, (None,))
    top_curves, top_ratio = heavy_top_case(args.repeat) if "a" in args.cases else none
    free_curves, free_ratio = torque_free_case(args.repeat) if "b" in args.cases else none
    gg_curves, gg_ratio, gg_floor = gravity_gradient_case(args.repeat) if "c" in args.cases else none + (None,)
    print(f"\nsummary: {CLOCK_NAME} time / DOP853's at the error DOP853 reaches with rtol = atol = 1e-12 "
          "(target <= 0.333)")
    print(f"  {'case':38s} {'splitting C':>12s} {'splitting Py':>13s} {'closed form':>12s}")
    for letter, name, ratios in (("a", "(a) heavy top (cos θ vs ℘)", top_ratio),
                                 ("b", "(b) torque-free (vs closed form)", free_ratio),
                                 ("c", "(c) gravity gradient n = 0.5 rad/s", gg_ratio)):
        if letter in args.cases:
            cells = [("not reached" if r is None else f"{r:.3f}") for r in ratios] + [""] * (3 - len(ratios))
            print(f"  {name:38s} {cells[0]:>12s} {cells[1]:>13s} {cells[2]:>12s}")
    if args.plot and args.cases == "abc":
        plot([("(a) heavy top: cos θ vs Weierstrass ℘", top_curves, top_ratio[0], None),
              ("(b) torque-free I = (1, 2, 3): state vs closed form", free_curves, free_ratio[0], None),
              ("(c) gravity gradient n = 0.5 rad/s: state vs DOP853 3e-14", gg_curves, gg_ratio[0], gg_floor)],
             args.plot)


if __name__ == "__main__":
    main()
