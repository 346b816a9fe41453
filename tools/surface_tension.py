#!/usr/bin/env python3
"""Surface tension of the propellants along saturation: CoolProp fixtures and the fit.

Writes, relative to the repository root (the parent of this script's folder):

* ``tests/fixtures/fluids/{LH2,LOX,LCH4,LN2,nLH2}_sigma.csv`` -- CoolProp surface tension
  (``I`` at ``Q=0``) at 41 temperatures uniform over the fitted range of the other
  properties, ``T_triple + 1 K .. 0.9 T_crit``;
* ``src/fluids/surface_tension.rs`` -- the coefficients of the corresponding-states form
  sigma = sigma_0 (1 - T/T_c)^n (Guggenheim 1945; CoolProp's own correlations are sums of such
  terms), fitted by least squares on ln sigma against ln(1 - T/T_c).

Usage::

    pip install CoolProp numpy
    python3 tools/surface_tension.py
"""

from __future__ import annotations

from pathlib import Path

import CoolProp
import CoolProp.CoolProp as CP
import numpy as np

from coolprop_fixtures import PROPELLANTS  # (file stem, CoolProp fluid), one list for both tools
N = 41


def main() -> None:
    root = Path(__file__).resolve().parent.parent
    rows = []
    for stem, name in PROPELLANTS:
        t_c = CP.PropsSI("Tcrit", name)
        t_min = CP.PropsSI("Ttriple", name) + 1.0
        t_max = 0.9 * t_c
        ts = np.linspace(t_min, t_max, N)
        sigma = np.array([CP.PropsSI("I", "T", t, "Q", 0, name) for t in ts])
        x = np.log(1.0 - ts / t_c)
        n, ln_s0 = np.polyfit(x, np.log(sigma), 1)
        s0 = float(np.exp(ln_s0))
        fit = s0 * (1.0 - ts / t_c) ** n
        err = float(np.max(np.abs(fit / sigma - 1.0)))
        rows.append((stem, s0, float(n), t_c, err))
        with open(root / "tests" / "fixtures" / "fluids" / f"{stem}_sigma.csv", "w") as f:
            f.write(f"# CoolProp {CoolProp.__version__} ({CoolProp.__gitrevision__}), fluid {name}\n")
            f.write("# surface tension along saturation, Q = 0\n")
            f.write("t_k,sigma_n_per_m\n")
            for t, s in zip(ts, sigma):
                f.write(f"{t:.12g},{s:.12g}\n")
    out = [
        "//! Surface tension along saturation, σ = σ_0 (1 − T/T_c)^n (Guggenheim 1945), fitted to",
        "//! CoolProp by `tools/surface_tension.py` (generated: do not edit). The fixtures",
        "//! `tests/fixtures/fluids/*_sigma.csv` check it (`tests/fluids.rs`).",
        "",
        "/// σ_0 (N/m), n and T_c (K) of one propellant; the largest relative fit error over",
        "/// T_triple + 1 K .. 0.9 T_c in the comment.",
        "#[derive(Clone, Copy, Debug, PartialEq)]",
        "pub struct SurfaceTension {",
        "    pub sigma0_n_per_m: f64,",
        "    pub exponent: f64,",
        "    pub t_crit_k: f64,",
        "}",
        "",
    ]
    for stem, s0, n, t_c, err in rows:
        out += [
            f"/// {stem}: largest relative error {err:.2e}.",
            f"pub const {stem.upper()}: SurfaceTension = SurfaceTension {{",
            f"    sigma0_n_per_m: {s0!r},",
            f"    exponent: {n!r},",
            f"    t_crit_k: {t_c!r},",
            "};",
        ]
    (root / "src" / "fluids" / "surface_tension.rs").write_text("\n".join(out) + "\n")
    for r in rows:
        print(r)


if __name__ == "__main__":
    main()
