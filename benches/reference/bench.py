#!/usr/bin/env python3
"""Speed of the lumped right-hand side against same-work peers (issue 18): cryoslosh
(`examples/rhs_states.rs --time`: `Lanes` groups of `lanes::WIDTH` (16; 32 in an AVX-512 build), rayon on 1 and 2 threads), the numpy
port and the JAX port (`jax.jit` over arrays and `jax.jit(jax.vmap(...))`, CPU, float64), all
on the same states, in right-hand-side evaluations per second.

    python3 benches/reference/bench.py campaigns/mhtb_selfpress.toml [--rows 1000] [--seconds 2]
        [--tile 1] [--repeat 1]

It writes the states with the example (cargo run --release, CARGO_TARGET_DIR honoured), checks
the ports against them first (the figures of a wrong port mean nothing), then times. `--tile N`
repeats the rows N times for the Python peers (a larger batch amortises their per-call cost;
cryoslosh is timed on the rows themselves: its cost per evaluation does not depend on the batch).
`--repeat N` times every peer N times, interleaved, and keeps the best round of each.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import check  # noqa: E402
import lumped_rhs as L  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(HERE))


def example(args):
    # RHS_STATES_BIN: an rhs_states binary already built (else cargo builds and runs it).
    built = os.environ.get("RHS_STATES_BIN")
    cargo = ["cargo", "run", "--quiet", "--release", "--example", "rhs_states", "--"]
    cmd = ([built] if built else cargo) + args
    return subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, text=True).stdout


def timed(f, seconds):
    """Calls per second of `f` over about `seconds` (after one warm-up call)."""
    f()
    n, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        f()
        n += 1
    return n / (time.perf_counter() - start)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("campaign")
    ap.add_argument("--rows", type=int, default=1000)
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--tile", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=1)
    a = ap.parse_args()
    campaign = os.path.abspath(a.campaign)
    rust, results = {}, {}

    def keep(table, label, rate):
        table[label] = max(table.get(label, 0.0), rate)

    def time_rust(extra):
        cmd = [campaign, "--rows", str(a.rows), "--time", "--seconds", str(a.seconds)]
        out = example(cmd + extra)
        for t, r in re.findall(r"threads=(\d+) evals_per_s=([0-9.eE+-]+)", out):
            keep(rust, int(t), float(r))

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "states.parquet")
        time_rust(["--out", path])
        sens = check.sensitivity(path)
        for backend in ("numpy", "jax"):
            name, ref, mine, _ = check.evaluate(backend, path)
            ok, strict, _ = check.verdict(mine, ref, sens, 1e-9)
            if not ok:
                sys.exit(f"{backend} port differs from cryoslosh ({np.max(strict):.3e}); not timing it")
        constants, structure, cols = L.load(path)
        if a.tile > 1:
            cols = {k: np.tile(v, a.tile) for k, v in cols.items()}
        n = len(cols["dt"])

        m = L.Model("numpy", constants, structure)
        p, d, dt, s, _ = L.split(cols)

        import jax

        mj = L.Model("jax", constants, structure)
        xp = mj.b.xp
        pj, dj, dtj, sj, _ = L.split(cols, xp=xp)
        f_arr = jax.jit(lambda p, d, dt, s: xp.stack(mj.rhs(p, d, dt, s), axis=1))
        f_vmap = jax.jit(jax.vmap(lambda p, d, dt, s: xp.stack(mj.rhs(p, d, dt, s))))
        jitted = [("JAX jit (arrays)", f_arr), ("JAX jit(vmap)", f_vmap)]
        for label, f in jitted:
            t0 = time.perf_counter()
            f(pj, dj, dtj, sj).block_until_ready()
            print(f"{label}: first call (trace + compile) {time.perf_counter() - t0:.1f} s")
        # --repeat N: N interleaved rounds of every peer, each peer's best round kept (on a
        # shared machine the best round is the one least disturbed by other load).
        for round_ in range(a.repeat):
            if round_ > 0:
                time_rust([])
            keep(results, "numpy (vectorised over rows)", n * timed(lambda: m.rhs(p, d, dt, s), a.seconds))
            for label, f in jitted:
                rate = n * timed(lambda f=f: f(pj, dj, dtj, sj).block_until_ready(), a.seconds)
                keep(results, label, rate)

    if a.repeat > 1:
        print(f"\nbest of {a.repeat} interleaved rounds per peer")
    print(f"\n{name}: {a.rows} states (Python peers: batch of {n})")
    print(f"{'peer':<34} {'RHS evaluations/s':>18}")
    for t, r in sorted(rust.items()):
        print(f"{'cryoslosh Lanes, ' + str(t) + ' thread(s)':<34} {r:>18,.0f}")
    for label, r in results.items():
        print(f"{label:<34} {r:>18,.0f}")
    print("\nratios (cryoslosh / peer)")
    for t, r in sorted(rust.items()):
        for label, q in results.items():
            print(f"  cryoslosh {t} thread(s) / {label:<30} {r / q:8.2f}")


if __name__ == "__main__":
    main()
