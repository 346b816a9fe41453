#!/usr/bin/env python3
"""Equality check of the same-work peers: the numpy and JAX ports of the lumped right-hand side
(`lumped_rhs.py`) against cryoslosh's own rates on the rows of `examples/rhs_states.rs`.

    python3 benches/reference/check.py STATES.parquet [...] [--tol 1e-9] [--no-jax]

For every row and every state component i the error is

    |r_port[i] − r_rust[i]| / max(|r_rust[i]|, floor[i]),
    floor[i] = 1e-6 · max over the rows of |r_rust[i]|   (and at least 1e-300)

so a component that is ~0 in a row (a rate that vanishes there, e.g. the slosh rates of a
tank at rest, or the vent ledger of a closed valve) is held to 1e-9 of the largest value that
component takes in the file, not to 1e-9 of its own rounding noise.

Conditioning allowance. Some rates are a small difference of large terms: the evaporation rate
is K (P_sat(T_s) − P_v), and on a locked-up tank P_v sits within 1e-9 of P_sat (9e-5 Pa of
1.1e5 Pa), so a last-bit change of the ullage temperature (1e-15) moves that rate by 1e-6
relative. Rounding alone then decides those digits: the numpy port performs the Rust operations
in the same order, but rounds the multiply and the add of each of cryoslosh's fused
multiply-adds separately, and XLA's own exp/log do not round like glibc's. Such an element also
passes when its difference is within the rate's measured rounding sensitivity: `sens` = the
largest change of the numpy rate when every state slot is perturbed by ±SENS_ULPS units in the
last place (SENS_DRAWS random draws), times SENS_FACTOR, and never beyond ALLOWANCE_CAP relative
(the sensitivity comes from the port under test, so it must not be able to admit any error at
all: a 1e-5 corruption of the LCH4 coast's dU_u/dt passed until 2026-12-06; the largest allowed
element of any shipped campaign is 8.4e-7, lch4_coast's under JAX, README.md). The report counts
the elements that needed the allowance. A port error (a wrong term, a wrong branch) moves a rate
by far more than its rounding sensitivity and still fails.

The check fails (exit 1) when any element fails or any rate is NaN where cryoslosh's is not.
"""

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fluid_tank as F  # noqa: E402
import lumped_rhs as L  # noqa: E402

FLOOR_SHARE = 1e-6
ALLOWANCE_CAP = 1e-6
SENS_ULPS = 4.0
SENS_DRAWS = 4
SENS_FACTOR = 10.0


def slot(i):
    """Component i as `i (NAME)`."""
    i = int(i)
    return f"{i} ({F.SLOT_NAMES[i]})" if i < len(F.SLOT_NAMES) else str(i)


def errors(mine, ref):
    # nanmax: a rate that is NaN in some row (matched by the port) must not void the floor of
    # its whole column.
    with np.errstate(all="ignore"):
        scale = np.nan_to_num(np.nanmax(np.abs(ref), axis=0), nan=0.0)
    floor = np.maximum(FLOOR_SHARE * scale, 1e-300)
    err = np.abs(mine - ref) / np.maximum(np.abs(ref), floor)
    err = np.where(np.isnan(ref) & np.isnan(mine), 0.0, err)
    err = np.where(np.isnan(mine) != np.isnan(ref), np.inf, err)
    return err


def verdict(mine, ref, sens, tol):
    """(passes, relative errors with the allowed elements zeroed, allowed mask)."""
    err = errors(mine, ref)
    allowed = (err > tol) & (err <= ALLOWANCE_CAP) & (np.abs(mine - ref) <= sens)
    strict = np.where(allowed, 0.0, err)
    worst = float(np.max(strict))
    return worst <= tol and np.isfinite(worst), strict, allowed


def sensitivity(path):
    """Rounding sensitivity of each rate (rows x components), from the numpy port."""
    constants, structure, cols = L.load(path)
    m = L.Model("numpy", constants, structure)
    p, d, dt, s, _ = L.split(cols)
    base = np.stack(m.rhs(p, d, dt, s), axis=1)
    rng = np.random.default_rng(18)
    sens = np.zeros_like(base)
    for _ in range(SENS_DRAWS):
        sp = [v * (1.0 + SENS_ULPS * np.finfo(float).eps * rng.uniform(-1, 1, v.shape)) for v in s]
        with np.errstate(all="ignore"):
            moved = np.stack(m.rhs(p, d, dt, sp), axis=1)
        sens = np.maximum(sens, np.abs(moved - base))
    return SENS_FACTOR * sens


def evaluate(backend, path):
    constants, structure, cols = L.load(path)
    m = L.Model(backend, constants, structure)
    xp = m.b.xp
    p, d, dt, s, ref = L.split(cols, xp=xp)
    if backend == "jax":
        import jax

        f = jax.jit(lambda p, d, dt, s: xp.stack(m.rhs(p, d, dt, s), axis=1))
        mine = np.asarray(f(p, d, dt, s))
        # The per-instance form, vmapped: the same numbers.
        one = jax.jit(
            jax.vmap(lambda p, d, dt, s: xp.stack(m.rhs(p, d, dt, s)), in_axes=(0, 0, 0, 0))
        )
        mine_v = np.asarray(one(p, d, dt, s))
    else:
        mine = np.stack(m.rhs(p, d, dt, s), axis=1)
        mine_v = None
    return constants["campaign"], ref, mine, mine_v


def main():
    ap = argparse.ArgumentParser(
        description="Check the numpy and JAX ports against cryoslosh's right-hand sides.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    ap.add_argument("files", nargs="+", help="states written by `examples/rhs_states.rs`")
    ap.add_argument("--tol", type=float, default=1e-9, help="relative tolerance per element")
    ap.add_argument("--no-jax", action="store_true", help="check the numpy port only")
    a = ap.parse_args()
    backends = ["numpy"] + ([] if a.no_jax else ["jax"])
    ok = True
    for path in a.files:
        try:
            sens = sensitivity(path)
        except (NotImplementedError, KeyError, OSError) as e:
            # Unported input (insulation, other levels) or not a file of rhs_states.
            what = f"no cryoslosh_constants metadata ({e})" if isinstance(e, KeyError) else e
            print(f"{path}: cannot check: {what}", file=sys.stderr)
            sys.exit(2)
        for backend in backends:
            name, ref, mine, mine_v = evaluate(backend, path)
            for label, arr in [(backend, mine), (backend + "+vmap", mine_v)]:
                if arr is None:
                    continue
                # A NaN is the worst error there is (argmax and argsort would put it last).
                err = np.nan_to_num(errors(arr, ref), nan=np.inf)
                within = np.abs(arr - ref) <= sens
                allowed = (err > a.tol) & (err <= ALLOWANCE_CAP) & within
                err_strict = np.where(allowed, 0.0, err)
                worst = np.max(err_strict, axis=0)
                row, comp = np.unravel_index(np.argmax(err_strict), err.shape)
                bad = float(np.max(err_strict)) > a.tol or not np.isfinite(np.max(err_strict))
                ok &= not bad
                note = ""
                if allowed.any():
                    cmp = np.unravel_index(np.argmax(np.where(allowed, err, 0.0)), err.shape)
                    note = (
                        f"; {int(allowed.sum())} element(s) above {a.tol:g} within rounding "
                        f"sensitivity (largest {np.max(err[allowed]):.1e}, component {slot(cmp[1])})"
                    )
                print(
                    f"{name:<22} {label:<11} rows={ref.shape[0]} max_rel_err={np.max(err_strict):.3e} "
                    f"(component {slot(comp)}, row {row}) {'FAIL' if bad else 'ok'}{note}"
                )
                if bad:
                    for i in np.argsort(-worst)[:5]:
                        print(f"    component {slot(i)}: {worst[i]:.3e}")
    if not ok:
        print(f"same-work peers differ from cryoslosh by more than {a.tol:g}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
