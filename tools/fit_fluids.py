#!/usr/bin/env python3
"""Fit the `cryoslosh::fluids` coefficient table from the CoolProp fixtures.

Reads ``tests/fixtures/fluids/*.csv`` (written by ``tools/coolprop_fixtures.py``)
and writes ``src/fluids/table.rs``, relative to the repository root (the parent
of this script's folder, or ``--root DIR``). Needs only numpy.

Fit forms (see ``src/fluids/mod.rs`` for the evaluation side):

* Liquid side: one degree-7 polynomial (exactly 8 monomial coefficients,
  constant term first, for Horner) in ``x = (T - T_mid) / T_half`` for each of
  ln P_sat, rho_l, c_p_l, h_fg, k_l and ln mu_l. Solved in the Chebyshev basis
  (well conditioned), then converted to monomials. The objective is the
  maximum relative error at the fixture rows (the absolute error of ln P and
  ln mu), minimised by Lawson's iteratively re-weighted least squares started
  from the weighted least-squares solution.
* Vapour ideal-gas part: ``u0 / R = T Q(x)`` (plus a constant that the model's energy reference
  absorbs), ``Q`` a degree-15 polynomial in ``x = 2 (sqrt(T) - sqrt(T_lo)) / (sqrt(T_hi) -
  sqrt(T_lo)) - 1`` over the ideal-gas fixture's range, so that ``c_v0 / R = Q + Q'(x) T dx/dT``
  is its exact derivative (the ullage's Newton solve for T needs the pair consistent). Fitted by
  joint least squares on c_v0 (relative) and u0 (relative to its span) -- equilibrium
  para-hydrogen's rotational bump near 150 K is what needs the degree.
* Vapour / helium: power laws ``y = y_ref (T / t_ref)^n`` with
  ``t_ref = sqrt(T_lo T_hi)`` of the gas fixture's range, fitted for minimax
  relative error (exact for a fixed exponent, golden-section search on n).

The script checks that ln P_sat is strictly increasing and c_p_l positive on
[-1, 1], prints the max relative error per fluid and property (also with a
hold-out fit on every other row, and for an f32 Horner evaluation such as the
WGSL backend performs), and refuses to write the table if any error exceeds
the accuracy contract of ``tests/fluids.rs``.

Usage::

    python3 tools/coolprop_fixtures.py   # needs CoolProp
    python3 tools/fit_fluids.py
    cargo test --test fluids
"""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path

import numpy as np
from numpy.polynomial import chebyshev as C

R_UNIVERSAL = 8.314462618  # J/(mol K), must match cryoslosh::fluids::R_UNIVERSAL

NCOEF = 8
PROPELLANTS = [
    ("LH2", "Lh2", "Liquid hydrogen, equilibrium para-hydrogen (CoolProp `ParaHydrogen`)"),
    ("LOX", "Lox", "Liquid oxygen (CoolProp `Oxygen`)"),
    ("LCH4", "Lch4", "Liquid methane (CoolProp `Methane`)"),
    ("LN2", "Ln2", "Liquid nitrogen (CoolProp `Nitrogen`)"),
    ("nLH2", "NLh2", "Normal liquid hydrogen, 75 % ortho (CoolProp `Hydrogen`)"),
]
# property key -> (csv column, fitted in log?, contract tolerance as relative error)
LIQUID = {
    "ln_psat": ("psat_pa", True, 0.005),
    "rho_l": ("rho_l_kg_m3", False, 0.01),
    "cp_l": ("cp_l_j_kgk", False, 0.02),
    "h_fg": ("h_fg_j_kg", False, 0.01),
    "k_l": ("k_l_w_mk", False, 0.03),
    "ln_mu_l": ("mu_l_pa_s", True, 0.03),
    "ln_rho_v": ("rho_v_kg_m3", True, 0.005),
}
# Saturated-liquid enthalpy h_l (0 at t_min_k): largest error as a share of h_fg.
H_L_TOL = 2e-3
# Vapour virial form Z = 1 + sum_{k=1..4} (rho/rho_c)^k sum_{j=0..5} c_kj (tau - 1)^j, tau = T_c/T.
VIRIAL_K, VIRIAL_J = 4, 6
# Density contract of the virial fit (tests/fluids.rs): saturated vapour, superheated to 3 T_sat.
VIRIAL_TOL_SAT, VIRIAL_TOL_SUPER = 0.01, 0.02
# Vapour ideal-gas part (tests/fluids.rs): c_v0 relative, u0 as a share of its span over the range.
NIDEAL = 16
IDEAL_CV_TOL, IDEAL_U_TOL = 0.01, 1e-3
POWER_LAW_TOL = 0.15
# Para-hydrogen's rotational heat capacity peaks near 150 K and lifts its gas conductivity there
# by ~17 % above any single power law fitted over 14..400 K (normal hydrogen, 75 % ortho, has no
# such bump): the one documented exception to POWER_LAW_TOL (see src/fluids/mod.rs).
POWER_LAW_TOL_PARA_H2_K = 0.17


# ---------------------------------------------------------------- reading ---
def read_csv(path: Path) -> tuple[dict[str, float], list[str], dict[str, np.ndarray], str]:
    consts: dict[str, float] = {}
    version = ""
    header: list[str] | None = None
    rows: list[list[float]] = []
    for line in path.read_text().splitlines():
        line = line.strip()
        if not line:
            continue
        if line.startswith("#"):
            m = re.match(r"#\s*const\s+(\w+)\s*=\s*(\S+)", line)
            if m:
                consts[m.group(1)] = float(m.group(2))
            m = re.match(r"#\s*(CoolProp \S+ \(git revision \w+\))", line)
            if m:
                version = m.group(1)
            continue
        if header is None:
            header = line.split(",")
            continue
        rows.append([float(v) for v in line.split(",")])
    if header is None or not rows:
        raise SystemExit(f"{path}: no data")
    data = np.array(rows)
    return consts, header, {h: data[:, i] for i, h in enumerate(header)}, version


# ---------------------------------------------------------------- fitting ---
def fit_poly(x: np.ndarray, y: np.ndarray, log: bool) -> np.ndarray:
    """Degree-7 fit minimising max relative error; returns 8 monomial coefficients."""
    target = np.log(y) if log else y
    scale = np.ones_like(y) if log else 1.0 / np.abs(y)  # error -> relative
    V = C.chebvander(x, NCOEF - 1) * scale[:, None]
    b = target * scale

    def solve(w: np.ndarray) -> np.ndarray:
        sw = np.sqrt(w)
        c, *_ = np.linalg.lstsq(V * sw[:, None], b * sw, rcond=None)
        return c

    w = np.full(len(x), 1.0 / len(x))
    best = solve(w)
    best_err = np.max(np.abs(V @ best - b))
    for _ in range(400):  # Lawson iterations
        c = solve(w)
        e = np.abs(V @ c - b)
        if e.max() < best_err:
            best, best_err = c, e.max()
        w = w * e
        s = w.sum()
        if not np.isfinite(s) or s == 0.0:
            break
        w /= s
    mono = C.cheb2poly(best)
    out = np.zeros(NCOEF)
    out[: len(mono)] = mono
    return out


def fit_h_l(x: np.ndarray, h: np.ndarray, scale: np.ndarray, t_half: float) -> np.ndarray:
    """Saturated-liquid enthalpy h_l(x) = T_half * integral_{-1}^{x} sum a_i s^i ds, zero at x = -1
    by construction; minimax (Lawson) in the error h_fit - h divided by `scale` (h_fg). Returns the
    8 monomial coefficients a_i of dh_l/dT (J/(kg K)) in x."""
    # Basis T_k(x) - T_k(-1), k = 1..8 (Chebyshev, zero at -1), then differentiated.
    ks = np.arange(1, NCOEF + 1)
    V = np.stack([C.chebval(x, np.eye(NCOEF + 1)[k]) - (-1.0) ** k for k in ks], axis=1)
    V = V / scale[:, None]
    b = h / t_half / scale
    w = np.full(len(x), 1.0 / len(x))
    best, best_err = None, np.inf
    for _ in range(400):
        sw = np.sqrt(w)
        c, *_ = np.linalg.lstsq(V * sw[:, None], b * sw, rcond=None)
        e = np.abs(V @ c - b)
        if e.max() < best_err:
            best, best_err = c, e.max()
        w = w * e
        if not np.isfinite(w.sum()) or w.sum() == 0.0:
            break
        w /= w.sum()
    cheb = np.concatenate([[0.0], best])  # coefficients of T_0..T_8 (constant dropped)
    mono = C.cheb2poly(C.chebder(cheb))
    out = np.zeros(NCOEF)
    out[: len(mono)] = mono
    return out


def h_l_of(a: np.ndarray, x: np.ndarray, t_half: float) -> np.ndarray:
    """h_l(x) from the dh_l/dT coefficients (as src/fluids evaluates it)."""
    integ = np.concatenate([[0.0], a / np.arange(1, NCOEF + 1)])
    return t_half * (np.polynomial.polynomial.polyval(x, integ) - np.polynomial.polynomial.polyval(-1.0, integ))


def virial_z(c: np.ndarray, t_crit: float, rho_crit: float, t: np.ndarray, rho: np.ndarray, dt=np.float64):
    """(Z, u_res/(R T)) of the virial form, Horner in (tau - 1) then in rho/rho_c, in `dt`."""
    tau = (t_crit / t).astype(dt)
    y, r = tau - dt(1.0), (rho / rho_crit).astype(dt)
    cc = c.astype(dt).reshape(VIRIAL_K, VIRIAL_J)
    z = np.zeros_like(y)
    u = np.zeros_like(y)
    for k in range(VIRIAL_K, 0, -1):
        b = np.zeros_like(y)
        db = np.zeros_like(y)
        for j in range(VIRIAL_J - 1, -1, -1):
            b = b * y + cc[k - 1, j]
            if j > 0:
                db = db * y + dt(j) * cc[k - 1, j]
        z = (z + b) * r
        u = (u + tau * db / dt(k)) * r
    return 1.0 + z.astype(np.float64), u.astype(np.float64)


def fit_virial(t_crit: float, rho_crit: float, col: dict[str, np.ndarray]) -> np.ndarray:
    """Joint weighted least squares of Z - 1 (weight 1/Z: relative density) and u_res/(R T)
    (weight 0.3) at the fixture rows; both are linear in the coefficients."""
    t, rho = col["t_k"], col["rho_kg_m3"]
    tau = t_crit / t
    y, r = tau - 1.0, rho / rho_crit
    zc, uc = [], []
    for k in range(1, VIRIAL_K + 1):
        for j in range(VIRIAL_J):
            zc.append(y**j * r**k)
            uc.append((j * y ** max(j - 1, 0) if j > 0 else 0.0 * y) * tau * r**k / k)
    A = np.vstack([np.array(zc).T, np.array(uc).T])
    b = np.concatenate([col["z"] - 1.0, col["u_res_rt"]])
    w = np.concatenate([1.0 / col["z"], np.full(len(t), 0.3)])
    c, *_ = np.linalg.lstsq(A * w[:, None], b * w, rcond=None)
    return c


def virial_density(c, t_crit, rho_crit, r_spec, t, p):
    """Vapour density at (T, P) by Newton on P = rho R T Z(T, rho), started from the ideal gas."""
    rho = p / (r_spec * t)
    for _ in range(60):
        h = 1e-7 * rho
        f = rho * r_spec * t * virial_z(c, t_crit, rho_crit, t, rho)[0] - p
        fp = (rho + h) * virial_z(c, t_crit, rho_crit, t, rho + h)[0]
        fm = (rho - h) * virial_z(c, t_crit, rho_crit, t, rho - h)[0]
        rho = rho - f / (r_spec * t * (fp - fm) / (2 * h))
    return rho


def ideal_basis(t: np.ndarray, t_lo: float, t_hi: float, dtype=np.float64):
    """Columns of u0/R = T Q(x) and c_v0/R = Q + Q'(x) T dx/dT in the coefficients of Q."""
    s_lo, s_hi = math.sqrt(t_lo), math.sqrt(t_hi)
    s = np.sqrt(t)
    x = 2.0 * (s - s_lo) / (s_hi - s_lo) - 1.0
    g = s / (s_hi - s_lo)
    vu = np.column_stack([t * x**k for k in range(NIDEAL)])
    vc = np.column_stack([x**k + (k * x ** max(k - 1, 0) * g if k > 0 else 0.0 * x) for k in range(NIDEAL)])
    return vu.astype(dtype), vc.astype(dtype), x


def fit_ideal(consts: dict[str, float], col: dict[str, np.ndarray], r_spec: float):
    """Coefficients of Q and the errors (c_v0 relative, u0 share of span, c_v0 in f32)."""
    t_lo, t_hi = consts["fit_t_lo_k"], consts["fit_t_hi_k"]
    t, cv, u = col["t_k"], col["cv0_j_kgk"] / r_spec, col["u0_j_kg"] / r_spec
    vu, vc, x = ideal_basis(t, t_lo, t_hi)
    span = float(u.max() - u.min())
    wu, wc = 50.0 / span, 1.0 / cv
    ones = np.ones((len(t), 1))
    a = np.vstack([np.hstack([vu, -ones]) * wu, np.hstack([vc, 0.0 * ones]) * wc[:, None]])
    b = np.concatenate([u * wu, cv * wc])
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    c, shift = sol[:NIDEAL], sol[NIDEAL]
    e_cv = float(np.max(np.abs(vc @ c / cv - 1.0)))
    e_u = float(np.max(np.abs(vu @ c - shift - u)) / span)
    # f32 Horner as the WGSL backend evaluates c_v0 = Q + Q' g
    c32, x32 = c.astype(np.float32), x.astype(np.float32)
    q, dq = np.zeros_like(x32), np.zeros_like(x32)
    for k in range(NIDEAL - 1, -1, -1):
        dq = dq * x32 + q if k < NIDEAL - 1 else dq
        q = q * x32 + c32[k]
    g32 = (np.sqrt(t) / (math.sqrt(t_hi) - math.sqrt(t_lo))).astype(np.float32)
    e32 = float(np.max(np.abs((q + dq * g32).astype(np.float64) / cv - 1.0)))
    return c, e_cv, e_u, e32


def horner(c: np.ndarray, x: np.ndarray) -> np.ndarray:
    acc = np.full_like(x, c[-1])
    for a in c[-2::-1]:
        acc = acc * x + a
    return acc


def rel_err(c: np.ndarray, x: np.ndarray, y: np.ndarray, log: bool, dtype=np.float64) -> float:
    v = horner(c.astype(dtype), x.astype(dtype)).astype(np.float64)
    if log:
        v = np.exp(v)
    return float(np.max(np.abs(v / y - 1.0)))


def fit_power_law(t: np.ndarray, y: np.ndarray, t_ref: float) -> tuple[float, float, float]:
    """Minimax relative error power law: returns (y_ref, exponent, max rel error)."""
    lt = np.log(t / t_ref)

    def for_n(n: float) -> tuple[float, float]:
        q = np.exp(n * lt) / y  # fit / data ratio for y_ref = 1
        a = 2.0 / (q.max() + q.min())  # equalises the over- and under-shoot
        return a, (q.max() - q.min()) / (q.max() + q.min())

    grid = np.linspace(-1.0, 3.0, 4001)
    errs = [for_n(n)[1] for n in grid]
    i = int(np.argmin(errs))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    g = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(200):
        m1, m2 = hi - g * (hi - lo), lo + g * (hi - lo)
        if for_n(m1)[1] < for_n(m2)[1]:
            hi = m2
        else:
            lo = m1
    n = 0.5 * (lo + hi)
    a, _ = for_n(n)
    err = float(np.max(np.abs(a * np.exp(n * lt) / y - 1.0)))
    return float(a), float(n), err


# ---------------------------------------------------------------- output ----
def lit(v: float) -> str:
    """Shortest round-trip f64 literal, valid Rust."""
    s = repr(float(v))
    if s in ("nan", "inf", "-inf"):
        raise SystemExit(f"non-finite coefficient {s}")
    s = s.replace("e+", "e")
    if "." not in s and "e" not in s:
        s += ".0"
    return s


def arr(name: str, c: np.ndarray) -> list[str]:
    return [f"    {name}: ["] + [f"        {lit(v)}," for v in c] + ["    ],"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    args = ap.parse_args()
    fix = args.root / "tests" / "fixtures" / "fluids"
    out_path = args.root / "src" / "fluids" / "table.rs"

    failures: list[str] = []
    report: list[str] = []
    blocks: list[str] = []
    versions: set[str] = set()

    for stem, _variant, desc in PROPELLANTS:
        consts, _, col, version = read_csv(fix / f"{stem}.csv")
        versions.add(version)
        t = col["t_k"]
        t_min, t_max = consts["t_min_k"], consts["t_max_k"]
        t_mid, t_half = 0.5 * (t_min + t_max), 0.5 * (t_max - t_min)
        x = (t - t_mid) / t_half
        coefs: dict[str, np.ndarray] = {}
        line = [f"{stem:5}"]
        for key, (cname, log, tol) in LIQUID.items():
            y = col[cname]
            c = fit_poly(x, y, log)
            coefs[key] = c
            err = rel_err(c, x, y, log)
            err32 = rel_err(c, x, y, log, np.float32)
            ho = fit_poly(x[::2], y[::2], log)
            err_ho = rel_err(ho, x[1::2], y[1::2], log)
            line.append(f"{key}={err:.2e} (holdout {err_ho:.2e}, f32 {err32:.2e})")
            if err > tol:
                failures.append(f"{stem} {key}: {err:.3e} > {tol}")
        report.append("  ".join(line))

        # sanity of the shapes the Rust side relies on
        xs = np.linspace(-1.0, 1.0, 20001)
        dl = horner(np.polynomial.polynomial.polyder(coefs["ln_psat"]), xs)
        if not np.all(dl > 0.0):
            failures.append(f"{stem}: ln P_sat fit not strictly increasing on [-1, 1]")
        if not np.all(horner(coefs["cp_l"], xs) > 0.0):
            failures.append(f"{stem}: c_p fit not positive on [-1, 1]")
        for key in ("rho_l", "h_fg", "k_l"):
            if not np.all(horner(coefs[key], xs) > 0.0):
                failures.append(f"{stem}: {key} fit not positive on [-1, 1]")

        vconsts, _, vcol, version = read_csv(fix / f"{stem}_vapor.csv")
        versions.add(version)
        t_lo, t_hi = vconsts["fit_t_min_k"], vconsts["fit_t_max_k"]
        t_ref = math.sqrt(t_lo * t_hi)
        k_ref, k_exp, k_err = fit_power_law(vcol["t_k"], vcol["k_w_mk"], t_ref)
        mu_ref, mu_exp, mu_err = fit_power_law(vcol["t_k"], vcol["mu_pa_s"], t_ref)
        report.append(f"{stem:5} vapour k={k_err:.3e} (n={k_exp:.4f})  mu={mu_err:.3e} (n={mu_exp:.4f})")
        for nm, e in (("k_v", k_err), ("mu_v", mu_err)):
            tol = POWER_LAW_TOL_PARA_H2_K if (stem, nm) == ("LH2", "k_v") else POWER_LAW_TOL
            if e > tol:
                failures.append(f"{stem} {nm}: {e:.3e} > {tol}")

        h_fg = col["h_fg_j_kg"]
        dh_l = fit_h_l(x, col["h_l_j_kg"], h_fg, t_half)
        h_err = float(np.max(np.abs(h_l_of(dh_l, x, t_half) - col["h_l_j_kg"]) / h_fg))
        ho = fit_h_l(x[::2], col["h_l_j_kg"][::2], h_fg[::2], t_half)
        h_err_ho = float(np.max(np.abs(h_l_of(ho, x[1::2], t_half) - col["h_l_j_kg"][1::2]) / h_fg[1::2]))
        report.append(f"{stem:5} h_l/h_fg={h_err:.2e} (holdout {h_err_ho:.2e})")
        if h_err > H_L_TOL:
            failures.append(f"{stem} h_l: {h_err:.3e} of h_fg > {H_L_TOL}")
        if not np.all(horner(dh_l, xs) > 0.0):
            failures.append(f"{stem}: dh_l/dT fit not positive on [-1, 1]")

        econsts, _, ecol, version = read_csv(fix / f"{stem}_eos.csv")
        versions.add(version)
        t_crit, rho_crit = consts["t_crit_k"], consts["rho_crit_kg_per_m3"]
        r_spec = R_UNIVERSAL / consts["molar_mass_kg_per_mol"]
        virial = fit_virial(t_crit, rho_crit, ecol)
        rho_fit = virial_density(virial, t_crit, rho_crit, r_spec, ecol["t_k"], ecol["p_pa"])
        d_err = np.abs(rho_fit / ecol["rho_kg_m3"] - 1.0)
        kind = ecol["kind"]
        z32, _ = virial_z(virial, t_crit, rho_crit, ecol["t_k"], ecol["rho_kg_m3"], np.float32)
        _, u_fit = virial_z(virial, t_crit, rho_crit, ecol["t_k"], ecol["rho_kg_m3"])
        e_sat, e_sup, e_warm = (float(d_err[kind == k].max()) for k in (0, 1, 2))
        e_u = float(np.max(np.abs(u_fit - ecol["u_res_rt"])))
        e32 = float(np.max(np.abs(z32 / ecol["z"] - 1.0)))
        report.append(
            f"{stem:5} virial rho: sat {e_sat:.1e} superheated {e_sup:.1e} beyond {e_warm:.1e}"
            f"  u_res/RT {e_u:.1e}  Z in f32 {e32:.1e}"
        )
        if e_sat > VIRIAL_TOL_SAT or e_sup > VIRIAL_TOL_SUPER:
            failures.append(f"{stem} virial density: sat {e_sat:.2e}, superheated {e_sup:.2e}")

        iconsts, _, icol, version = read_csv(fix / f"{stem}_ideal_gas.csv")
        versions.add(version)
        ideal, e_cv0, e_u0, e_cv32 = fit_ideal(iconsts, icol, r_spec)
        report.append(f"{stem:5} ideal gas: c_v0 {e_cv0:.1e} (f32 {e_cv32:.1e})  u0 {e_u0:.1e} of span")
        if e_cv0 > IDEAL_CV_TOL or e_u0 > IDEAL_U_TOL:
            failures.append(f"{stem} ideal gas: c_v0 {e_cv0:.2e}, u0 {e_u0:.2e}")

        b = [
            f"/// {desc}: constants and fit coefficients.",
            "///",
            f"/// Usable range {t_min:.3f} .. {t_max:.3f} K; vapour power laws fitted over "
            f"{t_lo:.3f} .. {t_hi:.1f} K at {vconsts['fit_p_pa']:.6g} Pa.",
            f"/// Max relative error at the fixture rows: P_sat {rel_err(coefs['ln_psat'], x, col['psat_pa'], True):.1e}, "
            f"rho_l {rel_err(coefs['rho_l'], x, col['rho_l_kg_m3'], False):.1e}, "
            f"c_p {rel_err(coefs['cp_l'], x, col['cp_l_j_kgk'], False):.1e},",
            f"/// h_fg {rel_err(coefs['h_fg'], x, col['h_fg_j_kg'], False):.1e}, "
            f"k_l {rel_err(coefs['k_l'], x, col['k_l_w_mk'], False):.1e}, "
            f"mu_l {rel_err(coefs['ln_mu_l'], x, col['mu_l_pa_s'], True):.1e}, "
            f"k_v {k_err:.1e}, mu_v {mu_err:.1e}, rho_v,sat {rel_err(coefs['ln_rho_v'], x, col['rho_v_kg_m3'], True):.1e};",
            f"/// h_l {h_err:.1e} of h_fg; virial vapour density: saturated {e_sat:.1e}, superheated to",
            f"/// 3 T_sat {e_sup:.1e} (beyond, to 400 K: {e_warm:.1e}), u_res/(R T) {e_u:.1e} absolute;",
            f"/// ideal-gas c_v0 {e_cv0:.1e}, u0 {e_u0:.1e} of its span over "
            f"{iconsts['fit_t_lo_k']:.3f} .. {iconsts['fit_t_hi_k']:.0f} K.",
            f"pub const {stem.upper()}: FluidProps = FluidProps {{",
            f"    molar_mass_kg_per_mol: {lit(consts['molar_mass_kg_per_mol'])},",
            f"    t_triple_k: {lit(consts['t_triple_k'])},",
            f"    t_crit_k: {lit(consts['t_crit_k'])},",
            f"    p_crit_pa: {lit(consts['p_crit_pa'])},",
            f"    t_min_k: {lit(t_min)},",
            f"    t_max_k: {lit(t_max)},",
            f"    ideal_t_lo_k: {lit(iconsts['fit_t_lo_k'])},",
            f"    ideal_t_hi_k: {lit(iconsts['fit_t_hi_k'])},",
            f"    k_vapor_ref_w_per_m_k: {lit(k_ref)},",
            f"    k_vapor_exp: {lit(k_exp)},",
            f"    mu_vapor_ref_pa_s: {lit(mu_ref)},",
            f"    mu_vapor_exp: {lit(mu_exp)},",
            f"    vapor_t_ref_k: {lit(t_ref)},",
            f"    rho_crit_kg_per_m3: {lit(rho_crit)},",
        ]
        for key in LIQUID:
            b += arr(key, coefs[key])
        b += arr("dh_l_sat", dh_l)
        b += arr("vapor_virial", virial)
        b += arr("vapor_ideal", ideal)
        b.append("};")
        blocks.append("\n".join(b))

    hconsts, _, hcol, version = read_csv(fix / "GHe.csv")
    versions.add(version)
    h_ref_t = math.sqrt(hconsts["fit_t_min_k"] * hconsts["fit_t_max_k"])
    hk_ref, hk_exp, hk_err = fit_power_law(hcol["t_k"], hcol["k_w_mk"], h_ref_t)
    hm_ref, hm_exp, hm_err = fit_power_law(hcol["t_k"], hcol["mu_pa_s"], h_ref_t)
    report.append(f"GHe   k={hk_err:.3e} (n={hk_exp:.4f})  mu={hm_err:.3e} (n={hm_exp:.4f})")
    for nm, e in (("He k", hk_err), ("He mu", hm_err)):
        if e > POWER_LAW_TOL:
            failures.append(f"{nm}: {e:.3e} > {POWER_LAW_TOL}")
    blocks.append(
        "\n".join(
            [
                "/// Helium pressurant (CoolProp `Helium`): ideal-gas constants and power laws for k and",
                f"/// mu fitted at {hconsts['fit_p_pa']:.6g} Pa over {hconsts['fit_t_min_k']:g} .. "
                f"{hconsts['fit_t_max_k']:g} K (max relative error k {hk_err:.1e}, mu {hm_err:.1e}).",
                "pub const HELIUM: GasProps = GasProps {",
                f"    molar_mass_kg_per_mol: {lit(hconsts['molar_mass_kg_per_mol'])},",
                f"    cp_j_per_kg_k: {lit(hconsts['cp_j_per_kg_k'])},",
                f"    cv_j_per_kg_k: {lit(hconsts['cv_j_per_kg_k'])},",
                f"    k_ref_w_per_m_k: {lit(hk_ref)},",
                f"    k_exp: {lit(hk_exp)},",
                f"    mu_ref_pa_s: {lit(hm_ref)},",
                f"    mu_exp: {lit(hm_exp)},",
                f"    t_ref_k: {lit(h_ref_t)},",
                "};",
            ]
        )
    )

    print("\n".join(report))
    if len(versions) != 1:
        failures.append(f"fixtures from different CoolProp versions: {sorted(versions)}")
    if failures:
        raise SystemExit("not writing table.rs:\n  " + "\n  ".join(failures))

    (version,) = versions
    head = [
        "//! Fluid-property coefficient table: GENERATED, do not edit by hand.",
        "//!",
        "//! Generated by `tools/fit_fluids.py` from the fixtures in `tests/fixtures/fluids/`,",
        f"//! source data {version}.",
        "//! To regenerate (needs `pip install CoolProp numpy`):",
        "//!",
        "//! ```text",
        "//! python3 tools/coolprop_fixtures.py   # CoolProp -> tests/fixtures/fluids/*.csv",
        "//! python3 tools/fit_fluids.py         # fixtures -> src/fluids/table.rs",
        "//! ```",
        "//!",
        "//! Liquid-side arrays are monomial coefficients (constant term first) of degree-7",
        "//! polynomials in `x = (T - T_mid) / T_half`, `T_mid = (t_min_k + t_max_k) / 2`,",
        "//! `T_half = (t_max_k - t_min_k) / 2`; see [`super`] for how they are evaluated.",
        "",
        "use super::{FluidProps, GasProps};",
    ]
    text = "\n".join(head) + "\n\n" + "\n\n".join(blocks) + "\n"
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_text(text)
    print(f"wrote {out_path}")


if __name__ == "__main__":
    main()
