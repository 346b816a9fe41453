#!/usr/bin/env python3
"""Time to solution at equal accuracy (issue 18): whole-mission runs of one campaign's
dispersed instances by cryoslosh (CPU on 1 and 2 threads, optionally the GPU backend) and by the
numpy and JAX ports of the lumped right-hand side, all with the same integrator and step, and
the accuracy each reaches against a tight reference.

    python3 benches/reference/solution.py campaigns/mhtb_selfpress.toml [--instances 256]
        [--dt 32] [--gpu]

The same work: every peer integrates the same instances (`examples/rhs_states.rs --initial`:
the campaign's own dispersion samples, their initial states and parameters) with classical RK4
at the step `--dt` over the whole mission, as `cryoslosh run --set campaign.integrator=rk4`
does. The ports' final pressures are checked against cryoslosh's RK4 run first (a wrong port's
figures mean nothing). Accuracy: the relative error of the final pressure against cryoslosh's
Dormand-Prince run at rtol 1e-8 (atol 1e-11); cryoslosh's default Dormand-Prince run (rtol
1e-6) is timed and scored too. `docs/INTEGRATION.md` ("Cost against fixed-step RK4") finds the
RK4 step of equal accuracy per campaign: 32 s for the MHTB tank.

The ports integrate only campaigns without events: one phase with a constant drive, no relief
valve, pressurant or outflow (the MHTB tank). They have the right-hand side and the step, not
the engine's events (valve switching at a crossing, phase ends, depletion, merges). A campaign
with a relief valve or pressurization (`lch4_coast`, `lh2_upper_stage`) is timed for cryoslosh
alone: Dormand-Prince at the campaign's tolerances on 1 and 2 threads and RK4 at the campaign's
own steps, each scored on peak pressure, boil-off, vented mass and final pressure against
Dormand-Prince at rtol 1e-8.

cryoslosh's figures are the whole `run` process's wall time (start, campaign load, sampling,
integration, statistics, Parquet writing: set CRYOSLOSH_BIN, or cargo's own start is counted
too); the time `run` itself reports (`instance-steps in … s`: sampling, integration and writing
the instances, not the statistics) is printed beside it. The ports' are the integration loop
alone (states already in memory), which favours them. Until 2026-12-06 the reported time was the
figure, 12-15 % below the process's.
"""

import argparse
import os
import re
import sys
import tempfile
import time
import tomllib

import numpy as np
import pyarrow.parquet as pq

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import lumped_rhs as L  # noqa: E402
from bench import example, run_tool  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(HERE))


def cryoslosh(args):
    """`cryoslosh ARGS` (CRYOSLOSH_BIN, else `cargo run --release`); its stdout."""
    built = os.environ.get("CRYOSLOSH_BIN")
    cargo = ["cargo", "run", "--quiet", "--release", "--"]
    return run_tool(([built] if built else cargo) + args)


def run(campaign, n, out, sets, extra=()):
    """A `cryoslosh run` of `n` instances: (the process's wall time, the integration time it
    reports, final pressures by instance)."""
    args = ["run", campaign, "--instances", str(n), "--out", out]
    for s in sets:
        args += ["--set", s]
    t0 = time.perf_counter()
    text = cryoslosh(args + list(extra))
    process_s = time.perf_counter() - t0
    m = re.search(r"instance-steps in ([0-9.]+) s", text)
    if not m:
        sys.exit(f"no timing in cryoslosh's output:\n{text}")
    t = pq.read_table(os.path.join(out, "instances.parquet"))
    order = np.argsort(t.column("instance").to_numpy())
    return process_s, float(m.group(1)), t.column("final_pressure_pa").to_numpy()[order]


def rk4(rhs, s, dt, steps):
    """`steps` classical RK4 steps of `rhs` from the list of slot arrays `s`, as
    `model::rk4_step` (every stage evaluated with the step `dt`)."""
    for _ in range(steps):
        k1 = rhs(s)
        k2 = rhs([a + 0.5 * dt * b for a, b in zip(s, k1)])
        k3 = rhs([a + 0.5 * dt * b for a, b in zip(s, k2)])
        k4 = rhs([a + dt * b for a, b in zip(s, k3)])
        s = [a + dt / 6.0 * (b + 2.0 * c + 2.0 * e + f) for a, b, c, e, f in zip(s, k1, k2, k3, k4)]
    return s


def pressure(m, p, d, dt, s):
    """Ullage pressure at states `s`, Pa, by the numpy port (its derive step)."""
    with L.with_errstate(np):
        m.rhs(p, d, dt, s)  # sets the tank geometry derive reads
        return m.derive(p, s, d)["p_ullage"]


# Quantities of interest scored in the cryoslosh-only comparison, with the floor of each
# relative error as a share of the QoI's largest magnitude over the instances (a boil-off or a
# vented mass near zero in one instance is not a relative error of 1).
QOIS = ("peak_pressure_pa", "boiloff_kg", "vented_kg", "final_pressure_pa")
QOI_FLOOR = 1e-3


def qois(out):
    """The QOIS columns of a run's instances.parquet, by instance."""
    t = pq.read_table(os.path.join(out, "instances.parquet"))
    order = np.argsort(t.column("instance").to_numpy())
    return {q: t.column(q).to_numpy(zero_copy_only=False).astype(float)[order] for q in QOIS}


def qoi_errors(got, ref):
    """Each QoI's relative errors over the instances, floored as QOI_FLOOR says: (largest,
    99th percentile). A valve cycle that one run has and the other has not (a crack near the
    mission's end) shows in the largest and not in the percentile."""
    out = {}
    for q in QOIS:
        scale = np.maximum(np.abs(ref[q]), QOI_FLOOR * np.max(np.abs(ref[q])))
        scale[scale == 0] = 1.0
        e = np.abs(got[q] - ref[q]) / scale
        out[q] = (float(np.max(e)), float(np.percentile(e, 99)))
    return out


def events_only(campaign, n, gpu, tmp):
    """Time to solution of a campaign with events (relief valve, pressurization, several
    phases), which the ports cannot integrate: cryoslosh alone, Dormand-Prince at the campaign's
    tolerances (the default rtol 1e-6 unless it sets them) on 1 and 2 threads, and RK4 at the
    campaign's own steps, each scored on its QoIs against Dormand-Prince at rtol 1e-8."""
    ref_out = os.path.join(tmp, "ref")
    run(campaign, n, ref_out, ["campaign.integrator=dopri5", "campaign.rtol=1e-8", "campaign.atol=1e-11"])
    ref = qois(ref_out)
    cases = [
        ("cryoslosh dopri5 (campaign tolerances), 1 thread", ["campaign.integrator=dopri5"], ["--threads", "1"]),
        ("cryoslosh dopri5 (campaign tolerances), 2 threads", ["campaign.integrator=dopri5"], ["--threads", "2"]),
        ("cryoslosh RK4 (campaign steps), 2 threads", ["campaign.integrator=rk4"], ["--threads", "2"]),
    ]
    if gpu:
        cases += [
            ("cryoslosh dopri5, GPU backend", ["campaign.integrator=dopri5"], ["--backend", "gpu"]),
            ("cryoslosh RK4 (campaign steps), GPU backend", ["campaign.integrator=rk4"], ["--backend", "gpu"]),
        ]
    print(f"\n{os.path.basename(campaign)}: {n} instances; the ports have no events, so cryoslosh alone")
    print(f"error: relative error against dopri5 at rtol 1e-8 (floor {QOI_FLOOR:g} of the QoI's largest), largest (99th percentile) over the instances")
    print(f"{'run':<52} {'s':>8} {'instances/s':>12} {'own s':>8}  " + " ".join(f"{q:>17}" for q in QOIS))
    for k, (label, sets, extra) in enumerate(cases):
        out = os.path.join(tmp, f"e{k}")
        if "GPU" in label:
            run(campaign, n, out, sets, extra)  # first: the kernel's compilation
        secs, reported, _ = run(campaign, n, out + "b", sets, extra)
        err = qoi_errors(qois(out + "b"), ref)
        print(f"{label:<52} {secs:8.3f} {n / secs:12,.0f} {reported:8.3f}  " + " ".join(f"{err[q][0]:8.1e} ({err[q][1]:6.0e})" for q in QOIS))


def main():
    ap = argparse.ArgumentParser(
        description="Time to solution at equal accuracy: cryoslosh against its numpy and JAX ports.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    ap.add_argument("campaign", help="a campaign TOML")
    ap.add_argument("--instances", type=int, default=256, help="dispersed instances")
    ap.add_argument(
        "--dt", type=float, default=32.0,
        help="RK4 step, s, for a campaign without events (ignored for one with events)",
    )
    ap.add_argument("--gpu", action="store_true", help="also time `--backend gpu`")
    a = ap.parse_args()
    campaign = os.path.abspath(a.campaign)
    n = a.instances
    rk4_sets = ["campaign.integrator=rk4", f"campaign.dt_s={a.dt}"]
    with tempfile.TemporaryDirectory() as tmp:
        start = os.path.join(tmp, "start.parquet")
        # The structure (read from the first row) at the campaign's own step, from one instance:
        # `--dt` is for the ports, and a campaign with events (not ported) may refuse it (a step
        # must resolve its slosh period).
        probe = os.path.join(tmp, "probe.parquet")
        example([campaign, "--initial", "--instances", "1", "--out", probe])
        _, structure, _ = L.load(probe)
        if structure["has_relief"] or structure["has_pressurization"]:
            return events_only(campaign, n, a.gpu, tmp)
        example([campaign, "--initial", "--instances", str(n), "--out", start, "--set", f"campaign.dt_s={a.dt}"])
        constants, structure, cols = L.load(start)
        p, d, dt, s0, _ = L.split(cols)
        if np.any(d["d_burning"]) or not np.all(dt == a.dt):
            sys.exit("expected a hold phase at the given step")
        with open(campaign, "rb") as f:
            duration = float(tomllib.load(f)["phases"][0]["duration_s"])
        steps = int(round(duration / a.dt))
        if abs(steps * a.dt - duration) > 1e-9 * duration:
            sys.exit(f"--dt {a.dt} does not divide the phase's {duration} s")

        # cryoslosh: the reference, the default tolerances, and RK4 at the step.
        _, _, ref = run(campaign, n, os.path.join(tmp, "ref"), ["campaign.integrator=dopri5", "campaign.rtol=1e-8", "campaign.atol=1e-11"])
        rows, reported_s = [], {}
        for label, sets, extra in [
            ("cryoslosh dopri5 (rtol 1e-6), 2 threads", ["campaign.integrator=dopri5"], ["--threads", "2"]),
            ("cryoslosh RK4, 1 thread", rk4_sets, ["--threads", "1"]),
            ("cryoslosh RK4, 2 threads", rk4_sets, ["--threads", "2"]),
        ] + ([("cryoslosh RK4, GPU backend", rk4_sets, ["--backend", "gpu"])] if a.gpu else []):
            out = os.path.join(tmp, f"r{len(rows)}")
            if "GPU" in label:
                run(campaign, n, out, sets, extra)  # first: the kernel's compilation
            secs, reported, fin = run(campaign, n, out + "b", sets, extra)
            rows.append((label, secs, fin))
            reported_s[label] = reported
        cryo_rk4 = rows[1][2]

        # The ports: numpy vectorised over instances; JAX with the RK4 step jitted.
        m = L.Model("numpy", constants, structure)
        rhs = lambda s: m.rhs(p, d, dt, s)  # noqa: E731
        t0 = time.perf_counter()
        s = rk4(rhs, s0, a.dt, steps)
        secs = time.perf_counter() - t0
        rows.append(("numpy RK4 (vectorised)", secs, pressure(m, p, d, dt, s)))

        import jax

        mj = L.Model("jax", constants, structure)
        xp = mj.b.xp
        pj, dj, dtj, sj, _ = L.split(cols, xp=xp)
        step = jax.jit(lambda s: tuple(rk4(lambda u: mj.rhs(pj, dj, dtj, list(u)), list(s), a.dt, 1)))
        t0 = time.perf_counter()
        sj = step(tuple(sj))
        jax.block_until_ready(sj)
        compile_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        for _ in range(steps - 1):
            sj = step(sj)
        jax.block_until_ready(sj)
        secs = (time.perf_counter() - t0) * steps / (steps - 1)
        fin = pressure(m, p, d, dt, [np.asarray(x) for x in sj])
        rows.append((f"JAX RK4 (step jitted; compile {compile_s:.1f} s not counted)", secs, fin))

    # The f64 peers only: the GPU backend's f32 kernel is held to the CPU by tests/gpu_parity.rs.
    worst = max(
        np.max(np.abs(f - cryo_rk4) / np.abs(cryo_rk4)) for label, _, f in rows if "RK4" in label and "GPU" not in label
    )
    if worst > 1e-8:
        sys.exit(f"a peer's RK4 final pressure differs from cryoslosh's by {worst:.2e}: not the same work")
    print(f"\n{os.path.basename(campaign)}: {n} instances, {steps} RK4 steps of {a.dt} s ({4 * steps} evaluations)")
    print(f"peers' RK4 final pressures equal cryoslosh's within {worst:.1e} (relative)")
    if not os.environ.get("CRYOSLOSH_BIN"):
        print("note: CRYOSLOSH_BIN not set: cryoslosh's times include `cargo run`'s own start")
    print(f"{'run':<58} {'s':>8} {'instances/s':>12} {'error':>9}  run's reported s (sampling, integration, instances)")
    for label, secs, fin in rows:
        err = np.max(np.abs(fin - ref) / np.abs(ref))
        own = f"{reported_s[label]:8.3f}" if label in reported_s else ""
        print(f"{label:<58} {secs:8.3f} {n / secs:12,.0f} {err:9.1e}  {own}")
    base = n / rows[2][1]
    print("\ncryoslosh RK4 2 threads / peer (instances/s)")
    for label, secs, _ in rows[3:]:
        print(f"  / {label:<56} {base / (n / secs):8.2f}")


if __name__ == "__main__":
    main()
