"""Generate src/model/slosh_table.rs and tests/fixtures/slosh/reference_2x.csv from tools/slosh_fem.py.

    python3 tools/slosh_tables.py            # tables (n = 16), verification, 2x fixture (n = 32)
    python3 tools/slosh_tables.py --check    # only re-measure the interpolation error
    python3 tools/slosh_tables.py --cached   # reuse the last run's tables (/tmp/slosh_tabs.npz)

Run by hand (numpy + scipy, a few minutes on two cores); CI does not run it. The interpolation
below is the one src/model/slosh.rs and shaders/model.wgsl implement: change all three together.

Tables (all lengths over the tank radius R; k = dome ratio, L = barrel length):
  BOTTOM[k][sigma]   surface in the bottom dome, sigma = sqrt(z / (k R)) in [0, 1]:
                     (omega^2 R/g, m_n/m_l) for modes 1, 2.
  BARREL[k][h]       surface in the barrel, h = (z - k R)/R = 3 x^2, x in [0, 1] (nodes uniform in x):
                     (omega^2 R/g, m_n/(rho R^3)); deeper is the deep-barrel limit (clamped).
  TOP[k][beta][u]    surface in the top dome, u = (z - k R - L)/(k R) in [0, 0.96], r_s = R sqrt(1-u^2):
                     (omega^2 r_s/g, m_n/(rho r_s^3)); beta = exp(-2 xi_1 L / R) carries the
                     liquid below (beta = 1: no barrel, L = 0; beta = 0: deep, computed at L = 3R).
Interpolation: linear in log2 k, linear in beta, Catmull-Rom along sigma, h, u (end nodes
extended linearly).
"""

import math
import os
import sys
from multiprocessing import Pool

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from slosh_fem import XI, Wall, solve  # noqa: E402

N_TABLE = 16
LOG2K = np.arange(-3.5, 1.75 + 1e-9, 0.25)  # k = 0.088 .. 3.36 (inputs: 0.1 .. 3)
SIGMA = np.linspace(0.0, 1.0, 21)
HBAR = 3.0 * np.linspace(0.0, 1.0, 25) ** 2  # dense above the bottom dome
UTOP = np.linspace(0.0, 0.96, 17)
BETA = np.linspace(0.0, 1.0, 5)
L_DEEP = 3.0
RS_MIN = 0.05  # smallest free-surface radius / R the model uses (a full domed tank)


def beta_length(b):
    return L_DEEP if b <= 0.0 else -math.log(b) / (2 * XI[0])


def quantities(args):
    region, k, L, x, n = args
    w = Wall("capsule", k, L)
    if region == "bottom":
        if x == 0.0:
            return None
        zs = k * x * x
    elif region == "barrel":
        zs = k + x
    else:
        zs = k + L + k * x
    res = solve(w, zs, n)
    rs = res[0]["rs"]
    out = []
    for m in res:
        if region == "bottom":
            out += [m["lam"], m["ratio"]]
        elif region == "barrel":
            out += [m["lam"], m["mhat"]]
        else:
            out += [m["lam"] * rs, m["mhat"] / rs**3]
    return out


def build(pool, n=N_TABLE, ks=None):
    ks = 2.0**LOG2K if ks is None else ks
    jobs = [("bottom", k, 0.0, s, n) for k in ks for s in SIGMA]
    bottom = np.array([q if q is not None else [0] * 4 for q in pool.map(quantities, jobs)])
    bottom = bottom.reshape(len(ks), len(SIGMA), 4)
    # Empty limit: omega^2 = g / (pole curvature radius R / k) for mode 1 (all liquid moves),
    # 7 g k / R for mode 2 (shallow water in a paraboloid, Lamb 1932 art. 193), no mass.
    bottom[:, 0, :] = np.stack([ks, np.ones_like(ks), 7 * ks, np.zeros_like(ks)], 1)
    jobs = [("barrel", k, L_DEEP + 1.0, h, n) for k in ks for h in HBAR]
    barrel = np.array(pool.map(quantities, jobs)).reshape(len(ks), len(HBAR), 4)
    jobs = [("top", k, beta_length(b), u, n) for k in ks for b in BETA for u in UTOP]
    top = np.array(pool.map(quantities, jobs)).reshape(len(ks), len(BETA), len(UTOP), 4)
    return bottom, barrel, top


def catmull(nodes_count, x):
    """Indices and weights of the Catmull-Rom interpolant at grid coordinate x in [0, n-1],
    with the end intervals using a linearly extended ghost node."""
    x = min(max(x, 0.0), nodes_count - 1.0)
    i = min(int(math.floor(x)), nodes_count - 2)
    t = x - i
    w = [
        0.5 * (-t**3 + 2 * t * t - t),
        0.5 * (3 * t**3 - 5 * t * t + 2),
        0.5 * (-3 * t**3 + 4 * t * t + t),
        0.5 * (t**3 - t * t),
    ]
    idx = [i - 1, i, i + 1, i + 2]
    if i == 0:  # ghost p(-1) = 2 p0 - p1
        w[1] += 2 * w[0]
        w[2] -= w[0]
        w[0] = 0.0
        idx[0] = 0
    if i + 2 > nodes_count - 1:  # ghost p(n) = 2 p(n-1) - p(n-2)
        w[2] += 2 * w[3]
        w[1] -= w[3]
        w[3] = 0.0
        idx[3] = nodes_count - 1
    return idx, w


def linear(nodes_count, x):
    x = min(max(x, 0.0), nodes_count - 1.0)
    i = min(int(math.floor(x)), nodes_count - 2)
    t = x - i
    return [i, i + 1], [1 - t, t]


def interp_fill(tab, grid, x, coord=None):
    """tab[..., node, 4] along its fill axis at physical coordinate x (grid coordinate coord)."""
    if coord is None:
        coord = (x - grid[0]) / (grid[1] - grid[0])
    idx, w = catmull(len(grid), coord)
    return sum(wi * tab[..., ii, :] for ii, wi in zip(idx, w))


def model(tabs, k, L, zs):
    """Interpolated (omega^2 R/g, m_n/m_l) per mode for a capsule (R = 1) at surface height zs."""
    bottom, barrel, top = tabs
    ik, wk = linear(len(LOG2K), (math.log2(k) - LOG2K[0]) / (LOG2K[1] - LOG2K[0]))
    w = Wall("capsule", k, L)
    v = w.volume(zs)
    out = np.zeros(4)
    for i, wi in zip(ik, wk):
        if zs <= k:
            q = interp_fill(bottom[i], SIGMA, math.sqrt(max(zs, 0.0) / k))
            val = q
        elif zs < k + L:
            q = interp_fill(barrel[i], HBAR, None, math.sqrt((zs - k) / HBAR[-1]) * (len(HBAR) - 1))
            val = np.array([q[0], q[1] / v, q[2], q[3] / v])
        else:
            u = min((zs - k - L) / k, 1.0)
            rs = max(math.sqrt(max(1 - u * u, 0.0)), RS_MIN)
            ib, wb = linear(len(BETA), math.exp(-2 * XI[0] * L) / BETA[-1] * (len(BETA) - 1))
            q = sum(wj * interp_fill(top[i, j], UTOP, u) for j, wj in zip(ib, wb))
            val = np.array([q[0] / rs, q[1] * rs**3 / v, q[2] / rs, q[3] * rs**3 / v])
        out += wi * val
    return out


def direct(k, L, zs, n):
    res = solve(Wall("capsule", k, L), zs, n)
    return np.array([res[0]["lam"], res[0]["ratio"], res[1]["lam"], res[1]["ratio"]]), res


def fill_height(k, L, fill):
    w = Wall("capsule", k, L)
    lo, hi = 0.0, w.height()
    target = fill * w.volume(w.height())
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if w.volume(mid) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _ref_job(a):
    k, L, fill, n = a
    zs = fill_height(k, L, fill)
    return (k, L, fill, zs) + tuple(direct(k, L, zs, n)[1])


def reference(pool, n):
    cases = [(1.0, 0.0), (0.5, 1.0), (2**-0.5, 1.0), (1.0, 1.0)]
    fills = [f / 100 for f in range(5, 96, 5)] + [0.01, 0.02]
    rows = pool.map(_ref_job, [(k, L, f, n) for k, L in cases for f in fills])
    return rows


def write_fixture(rows, path, n):
    with open(path, "w") as f:
        f.write(f"# GENERATED by tools/slosh_tables.py (tools/slosh_fem.py at n = {n}, twice the tables' resolution), do not edit.\n")
        f.write("# Lengths over the tank radius R; fill = liquid volume / tank volume; hinge = pendulum hinge height above the free surface.\n")
        f.write("shape,dome_ratio,cylinder_length_over_r,fill,level_over_r,mode,omega2_r_over_g,mass_ratio,length_over_r,hinge_over_r\n")
        for k, L, fill, zs, m1, m2 in sorted(rows, key=lambda r: (r[0], r[1], r[2])):
            shape = "sphere" if L == 0.0 and k == 1.0 else "capsule"
            for mode, m in ((1, m1), (2, m2)):
                f.write(f"{shape},{k:.6f},{L:.3f},{fill:.2f},{zs:.9f},{mode},{m['lam']:.7f},{m['ratio']:.7e},{m['length']:.7f},{m['hinge']:.7f}\n")


def fmt(a):
    """Seven significant digits, eight values a line (the file is `rustfmt::skip`)."""
    vals = [repr(float(f"{v:.7g}")) if abs(v) >= 1e-30 else "0.0" for v in np.asarray(a).ravel()]
    lines = [", ".join(vals[i : i + 8]) + "," for i in range(0, len(vals), 8)]
    return "\n    " + "\n    ".join(lines) + "\n"


def write_rust(tabs, path):
    bottom, barrel, top = tabs
    text = f"""//! GENERATED by tools/slosh_tables.py from tools/slosh_fem.py (n = {N_TABLE}), do not edit.
//!
//! Sloshing modes of capsules (and the sphere, k = 1 and L = 0) for the first two modes, the
//! layout and interpolation are described in src/model/slosh.rs and tools/slosh_tables.py.
//! Each node holds [a_1, b_1, a_2, b_2]; lengths over the tank radius R.
#![allow(
    clippy::approx_constant,
    reason = "solver output: a value near 1/√2 or √2 is a coincidence, not the constant"
)]

/// log2 of the first dome ratio node.
pub const LOG2K_0: f64 = {float(LOG2K[0])!r};
/// Step of log2 k between nodes.
pub const LOG2K_STEP: f64 = {float(LOG2K[1] - LOG2K[0])!r};
/// Number of dome-ratio nodes.
pub const NK: usize = {len(LOG2K)};
/// Nodes along sigma = sqrt(z / (k R)) in [0, 1] (bottom dome).
pub const N_SIGMA: usize = {len(SIGMA)};
/// Nodes along x = √(h / BARREL_H_MAX) in [0, 1], h = (z − k R) / R (barrel).
pub const N_BARREL: usize = {len(HBAR)};
/// Deepest tabulated barrel depth over R; deeper surfaces take its values.
pub const BARREL_H_MAX: f64 = {float(HBAR[-1])!r};
/// Nodes along u = (z − k R − L) / (k R) in [0, {float(UTOP[-1])!r}] (top dome).
pub const N_TOP: usize = {len(UTOP)};
/// Largest tabulated top-dome height u; fuller tanks take its values of ω² r_s/g and m/(ρ r_s³).
pub const TOP_U_MAX: f64 = {float(UTOP[-1])!r};
/// Nodes along beta = exp(−2 ξ_1 L / R) in [0, 1] (liquid below the top dome).
pub const N_BETA: usize = {len(BETA)};
/// Barrel length over R at which the deep (beta = 0) top-dome column was computed.
pub const TOP_DEEP_L: f64 = {float(L_DEEP)!r};

/// Bottom dome: [k][sigma] → (ω² R/g, m_n/m_l) per mode.
#[rustfmt::skip]
pub static BOTTOM: [f64; {bottom.size}] = [{fmt(bottom)}];

/// Barrel: [k][x] → (ω² R/g, m_n/(ρ R³)) per mode.
#[rustfmt::skip]
pub static BARREL: [f64; {barrel.size}] = [{fmt(barrel)}];

/// Top dome: [k][beta][u] → (ω² r_s/g, m_n/(ρ r_s³)) per mode.
#[rustfmt::skip]
pub static TOP: [f64; {top.size}] = [{fmt(top)}];
"""
    with open(path, "w") as f:
        f.write(text)


def verify(pool, tabs):
    """Interpolation error against direct solves at the tables' resolution, off the nodes."""
    cases = []
    for k in (0.1, 0.15, 0.3, 0.5, 0.6, 2**-0.5, 0.85, 1.0, 1.2, 1.6, 2.5, 3.0):
        for L in (0.0, 0.1, 0.3, 0.7, 1.0, 2.0, 4.0):
            for f in (0.03, 0.1, 0.2, 0.35, 0.5, 0.65, 0.8, 0.9, 0.97):
                cases.append((k, L, f))
    res = pool.map(_verify_job, [(k, L, f) for k, L, f in cases])
    worst = {}
    for (k, L, f), d in zip(cases, res):
        zs = fill_height(k, L, f)
        m = model(tabs, k, L, zs)
        err = np.abs(m / d - 1)
        region = "bottom" if zs <= k else ("barrel" if zs <= k + L else "top")
        key = (region, "L<0.5" if L < 0.5 else "L>=0.5")
        if err.max() > worst.get(key, (0,))[0]:
            worst[key] = (err.max(), k, L, f, err)
    for key, v in sorted(worst.items()):
        print(f"worst {key}: {v[0]:.2e} at k={v[1]:.3f} L={v[2]} fill={v[3]} (w1 m1 w2 m2 {np.array2string(v[4], precision=4)})")


def _verify_job(a):
    k, L, f = a
    return direct(k, L, fill_height(k, L, f), N_TABLE)[0]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    with Pool(2) as pool:
        cache = os.path.join("/tmp", "slosh_tabs.npz")
        if ("--check" in sys.argv or "--cached" in sys.argv) and os.path.exists(cache):
            d = np.load(cache)
            tabs = (d["bottom"], d["barrel"], d["top"])
            if len(tabs[0]) < len(LOG2K):  # a cached run on the first grid (k 0.25 .. 2): add the new k nodes
                ks = 2.0**LOG2K
                have = {round(float(k), 9): i for i, k in enumerate(2.0 ** np.arange(-2.0, 1.0 + 1e-9, 0.25))}
                new_ks = np.array([k for k in ks if round(float(k), 9) not in have])
                extra = build(pool, ks=new_ks)
                parts = []
                for t_old, t_new in zip(tabs, extra):
                    rows, j = [], 0
                    for k in ks:
                        key = round(float(k), 9)
                        if key in have:
                            rows.append(t_old[have[key]])
                        else:
                            rows.append(t_new[j])
                            j += 1
                    parts.append(np.array(rows))
                tabs = tuple(parts)
                np.savez(cache, bottom=tabs[0], barrel=tabs[1], top=tabs[2])
            if "--barrel" in sys.argv:
                ks = 2.0**LOG2K
                jobs = [("barrel", k, L_DEEP + 1.0, h, N_TABLE) for k in ks for h in HBAR]
                barrel = np.array(pool.map(quantities, jobs)).reshape(len(ks), len(HBAR), 4)
                tabs = (tabs[0], barrel, tabs[2])
                np.savez(cache, bottom=tabs[0], barrel=tabs[1], top=tabs[2])
        else:
            tabs = build(pool)
            np.savez(cache, bottom=tabs[0], barrel=tabs[1], top=tabs[2])
        if "--check" not in sys.argv:
            write_rust(tabs, os.path.join(root, "src/model/slosh_table.rs"))
        verify(pool, tabs)
        if "--check" not in sys.argv:
            rows = reference(pool, 2 * N_TABLE)
            os.makedirs(os.path.join(root, "tests/fixtures/slosh"), exist_ok=True)
            write_fixture(rows, os.path.join(root, "tests/fixtures/slosh/reference_2x.csv"), 2 * N_TABLE)


if __name__ == "__main__":
    main()
