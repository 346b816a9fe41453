#!/usr/bin/env python3
"""Generate CoolProp reference fixtures for the `cryoslosh::fluids` fits.

Writes, relative to the repository root (the parent of this script's folder,
or ``--root DIR``):

* ``tests/fixtures/fluids/{LH2,LOX,LCH4,LN2,nLH2}.csv`` (LH2 is equilibrium
  para-hydrogen, CoolProp ``ParaHydrogen``; nLH2 normal hydrogen, ``Hydrogen``) -- saturated-liquid
  properties (CoolProp ``Q=0``) at 121 temperatures spaced uniformly over the
  usable range ``T_min = T_triple + 1 K`` .. ``T_max = 0.93 * T_crit`` (0.93 so that
  LN2 at 2 MPa, T_sat = 0.916 T_crit, lies inside);
* ``tests/fixtures/fluids/{LH2,LOX,LCH4,LN2,nLH2}_vapor.csv`` -- dilute-gas
  thermal conductivity and viscosity on which the vapour power laws are
  fitted: 61 temperatures spaced uniformly in ln T over ``T_min .. 400 K`` at
  the fixed pressure ``P_fit = 0.5 * P_sat(T_min)`` (the largest "round" choice
  at which the gas is single-phase over the whole range; at tank pressures the
  dilute-gas transport properties differ from these only by the dense-gas
  excess, see ``src/fluids/mod.rs``);
* ``tests/fixtures/fluids/{stem}_eos.csv`` -- the vapour's real-gas state for the density-explicit
  virial fit of ``tools/fit_fluids.py``: compressibility Z and the residual internal energy
  u_res / (R T) = tau d(alpha_r)/d(tau) at 41 saturated-vapour points (kind 0, uniform in T over the
  usable range) and on 16 isobars (uniform in ln P from P_sat(t_min_k) to min(2 MPa, 0.9 P_crit)),
  14 temperatures each uniform in ln T from 1.001 T_sat(P) to max(3 T_sat(P), 400 K) (kind 1 up to
  3 T_sat, the acceptance range; kind 2 beyond it, where the fit is only constrained);
* ``tests/fixtures/fluids/{stem}_closed_tank.csv`` -- the equilibrium pressure-rise coefficient of a
  closed rigid tank, (dP/du) at constant mean density (Pa per J/kg: dP/dt = (dP/du) Q / m), from
  CoolProp's two-phase (rho, u) flash differenced over u +- 1 J/kg, at fills 10/25/50/90 % of
  saturated liquid and pressures 0.1, 0.6 and 2 MPa below 0.9 P_crit;
* ``tests/fixtures/fluids/{stem}_ideal_gas.csv`` -- the vapour's ideal-gas heat capacity and
  internal energy (CoolProp ``CP0MASS`` and ``HMASS`` at 1e-10 kg/m^3, less R T) at 241 temperatures
  uniform in sqrt(T) over ``t_min_k - 5 K .. 650 K`` (the ullage and pressurant-inlet range), and
  ``{stem}_warm_gas.csv`` -- the enthalpy a warm vapour carries above the saturated vapour at the
  same pressure, H(T, P) - H(P, Q=1), at 1.5 T_sat and those of 150, 300, 450, 600 K above
  1.2 T_sat, P = 0.1, 0.6, 2 MPa (below 0.9 P_crit), the check on an autogenous pressurant inlet;
* ``tests/fixtures/fluids/GHe.csv`` -- helium k and mu at 1 bar, 61
  temperatures spaced uniformly in ln T over 5 .. 400 K (gaseous at 1 bar).

Every file starts with ``#`` comment lines: the CoolProp version and git
revision, the CoolProp fluid string, units, and ``# const name = value`` lines
with the scalar constants that ``tools/fit_fluids.py`` copies into
``src/fluids/table.rs`` (so the fit script needs only numpy, not CoolProp).

Usage::

    pip install CoolProp numpy
    python3 tools/coolprop_fixtures.py          # then: python3 tools/fit_fluids.py
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import CoolProp
import CoolProp.CoolProp as CP
import numpy as np

R_UNIVERSAL = 8.314462618  # J/(mol K), must match cryoslosh::fluids::R_UNIVERSAL

# (file stem, CoolProp fluid string)
PROPELLANTS = [
    ("LH2", "ParaHydrogen"),
    ("LOX", "Oxygen"),
    ("LCH4", "Methane"),
    ("LN2", "Nitrogen"),
    ("nLH2", "Hydrogen"),
]
T_MAX_FRACTION = 0.93  # top of the usable range as a fraction of T_crit
N_LIQUID = 121  # rows per saturated-liquid fixture (uniform in T)
N_EOS_SAT, N_EOS_ISOBARS, N_EOS_T = 41, 16, 14  # vapour real-gas fixture grid
P_EOS_MAX = 2.0e6  # Pa, top of the superheated-vapour range (or 0.9 P_crit if lower)
CLOSED_TANK_P = (1.0e5, 6.0e5, 2.0e6)  # Pa
CLOSED_TANK_FILL = (0.10, 0.25, 0.50, 0.90)  # liquid volume fraction
N_VAPOR = 61  # rows per gas-phase fixture (uniform in ln T)
T_VAPOR_MAX = 400.0  # K, top of the gas-phase fit range
IDEAL_T_BELOW_MIN, IDEAL_T_MAX, N_IDEAL = 5.0, 650.0, 241  # ideal-gas fixture range and rows
WARM_GAS_T = (150.0, 300.0, 450.0, 600.0)  # K, warm-gas fixture temperatures (with 1.5 T_sat)
HE_T_MIN, HE_T_MAX, HE_P = 5.0, 400.0, 1.0e5  # helium range (K) and pressure (Pa)


def fmt(v: float) -> str:
    """12 significant digits: far below CoolProp's own uncertainty, keeps files small."""
    return f"{v:.12g}"


def version_lines(fluid: str) -> list[str]:
    return [
        f"# CoolProp {CoolProp.__version__} (git revision {CoolProp.__gitrevision__})",
        f"# CoolProp fluid string: {fluid}",
    ]


def write(path: Path, header: list[str], columns: list[str], rows: list[list[float]]) -> None:
    lines = header + [",".join(columns)]
    for row in rows:
        # Temperatures are written with repr() so T_min/T_max round-trip exactly.
        lines.append(",".join([repr(float(row[0]))] + [fmt(v) for v in row[1:]]))
    path.write_text("\n".join(lines) + "\n")
    size = path.stat().st_size
    print(f"wrote {path} ({len(rows)} rows, {size} bytes)")
    if size >= 30_000:
        raise SystemExit(f"{path} is {size} bytes, limit is 30 kB")


def ideal_gas_cp_cv(fluid: str, t: float, molar_mass: float) -> tuple[float, float]:
    """Ideal-gas cp0 from CoolProp (CP0MASS, at 1 Pa: pressure-independent);
    cv0 = cp0 - R_u/M with cryoslosh's R_u so that cp - cv == R_specific exactly."""
    cp0 = CP.PropsSI("CP0MASS", "T", t, "P", 1.0, fluid)
    return cp0, cp0 - R_UNIVERSAL / molar_mass


def propellant(root: Path, stem: str, fluid: str) -> None:
    m = CP.PropsSI("molar_mass", fluid)
    t_triple = CP.PropsSI("Ttriple", fluid)
    t_crit = CP.PropsSI("Tcrit", fluid)
    p_crit = CP.PropsSI("pcrit", fluid)
    t_min = t_triple + 1.0
    t_max = T_MAX_FRACTION * t_crit

    consts = [
        ("molar_mass_kg_per_mol", m),
        ("t_triple_k", t_triple),
        ("t_crit_k", t_crit),
        ("p_crit_pa", p_crit),
        ("t_min_k", t_min),
        ("t_max_k", t_max),
        ("rho_crit_kg_per_m3", CP.PropsSI("rhomass_critical", fluid)),
    ]
    const_lines = [f"# const {k} = {v!r}" for k, v in consts]

    # --- saturated liquid -------------------------------------------------
    ts = np.linspace(t_min, t_max, N_LIQUID)
    ts[0], ts[-1] = t_min, t_max
    rows = []
    h_l_min = CP.PropsSI("H", "T", t_min, "Q", 0, fluid)
    for t in ts:
        t = float(t)
        p = CP.PropsSI("P", "T", t, "Q", 0, fluid)
        rho = CP.PropsSI("D", "T", t, "Q", 0, fluid)
        cp = CP.PropsSI("C", "T", t, "Q", 0, fluid)
        h_fg = CP.PropsSI("H", "T", t, "Q", 1, fluid) - CP.PropsSI("H", "T", t, "Q", 0, fluid)
        k = CP.PropsSI("L", "T", t, "Q", 0, fluid)
        mu = CP.PropsSI("V", "T", t, "Q", 0, fluid)
        h_l = CP.PropsSI("H", "T", t, "Q", 0, fluid) - h_l_min
        rho_v = CP.PropsSI("D", "T", t, "Q", 1, fluid)
        vals = [t, p, rho, cp, h_fg, k, mu, h_l, rho_v]
        if not all(math.isfinite(v) and v >= 0 for v in vals) or t > t_min and h_l <= 0:
            raise SystemExit(f"{fluid}: bad CoolProp value at T={t}: {vals}")
        rows.append(vals)
    header = [
        f"# cryoslosh saturated-liquid fixture for {stem}, generated by tools/coolprop_fixtures.py",
        *version_lines(fluid),
        "# Saturated liquid (Q=0) along the saturation curve, "
        f"{N_LIQUID} rows uniform in T over [t_min_k, t_max_k]",
        f"# t_min_k = t_triple_k + 1 K, t_max_k = {T_MAX_FRACTION} * t_crit_k; h_fg = H(Q=1) - H(Q=0)",
        "# units: t_k [K], psat_pa [Pa], rho_l_kg_m3 [kg/m^3], cp_l_j_kgk [J/(kg K)], "
        "h_fg_j_kg [J/kg], k_l_w_mk [W/(m K)], mu_l_pa_s [Pa s], "
        "h_l_j_kg [J/kg] = H(Q=0) - H(Q=0, t_min_k), rho_v_kg_m3 [kg/m^3] (Q=1)",
        *const_lines,
    ]
    cols = [
        "t_k",
        "psat_pa",
        "rho_l_kg_m3",
        "cp_l_j_kgk",
        "h_fg_j_kg",
        "k_l_w_mk",
        "mu_l_pa_s",
        "h_l_j_kg",
        "rho_v_kg_m3",
    ]
    write(root / f"{stem}.csv", header, cols, rows)

    # --- dilute gas for the vapour power laws ----------------------------
    p_fit = 0.5 * CP.PropsSI("P", "T", t_min, "Q", 0, fluid)
    gas(
        root / f"{stem}_vapor.csv",
        stem,
        fluid,
        t_min,
        T_VAPOR_MAX,
        p_fit,
        "P_fit = 0.5 * P_sat(t_min_k): single-phase gas over the whole range",
        [("fit_t_min_k", t_min), ("fit_t_max_k", T_VAPOR_MAX), ("fit_p_pa", p_fit)],
    )


def vapor_eos(root: Path, stem: str, fluid: str) -> None:
    """Real-gas vapour states: Z and u_res/(R T) on saturation and superheated isobars."""
    st = CP.AbstractState("HEOS", fluid)
    t_min = CP.PropsSI("Ttriple", fluid) + 1.0
    t_crit = CP.PropsSI("Tcrit", fluid)
    p_crit = CP.PropsSI("pcrit", fluid)
    states = []
    for t in np.linspace(t_min, T_MAX_FRACTION * t_crit, N_EOS_SAT):
        st.update(CP.QT_INPUTS, 1.0, float(t))
        states.append((0, float(t), st.rhomass()))
    p_lo = CP.PropsSI("P", "T", t_min, "Q", 1, fluid)
    p_hi = min(P_EOS_MAX, 0.9 * p_crit)
    for p in np.exp(np.linspace(math.log(p_lo), math.log(p_hi), N_EOS_ISOBARS)):
        t_sat = CP.PropsSI("T", "P", float(p), "Q", 1, fluid)
        top = max(3.0 * t_sat, T_VAPOR_MAX)
        for t in np.exp(np.linspace(math.log(1.001 * t_sat), math.log(top), N_EOS_T)):
            st.update(CP.PT_INPUTS, float(p), float(t))
            kind = 1 if t <= 3.0 * t_sat * (1 + 1e-12) else 2
            states.append((kind, float(t), st.rhomass()))
    rows = []
    for kind, t, rho in states:
        st.update(CP.DmassT_INPUTS, rho, t)
        rows.append([t, rho, st.p(), st.compressibility_factor(), st.tau() * st.dalphar_dTau(), kind])
    header = [
        f"# cryoslosh vapour real-gas fixture for {stem}, generated by tools/coolprop_fixtures.py",
        *version_lines(fluid),
        f"# kind 0: saturated vapour, {N_EOS_SAT} rows uniform in T over [t_min_k, t_max_k];",
        f"# kind 1/2: {N_EOS_ISOBARS} isobars uniform in ln P over [P_sat(t_min_k), min(2 MPa, 0.9 P_crit)],",
        f"# {N_EOS_T} temperatures each uniform in ln T over [1.001 T_sat(P), max(3 T_sat(P), 400 K)]",
        "# (kind 1 up to 3 T_sat, kind 2 beyond). z = P / (rho R T); u_res_rt = tau d(alpha_r)/d(tau)",
        "# units: t_k [K], rho_kg_m3 [kg/m^3], p_pa [Pa], z [-], u_res_rt [-], kind [-]",
    ]
    write(root / f"{stem}_eos.csv", header, ["t_k", "rho_kg_m3", "p_pa", "z", "u_res_rt", "kind"], rows)


def ideal_gas(root: Path, stem: str, fluid: str) -> None:
    """Ideal-gas c_v0(T) and u0(T) of the vapour, and the enthalpy of warm vapour above saturation."""
    m = CP.PropsSI("molar_mass", fluid)
    r_spec = R_UNIVERSAL / m
    t_triple = CP.PropsSI("Ttriple", fluid)
    t_lo = t_triple + 1.0 - IDEAL_T_BELOW_MIN
    st = CP.AbstractState("HEOS", fluid)
    rows = []
    for s in np.linspace(math.sqrt(t_lo), math.sqrt(IDEAL_T_MAX), N_IDEAL):
        t = float(s * s)
        st.update(CP.DmassT_INPUTS, 1e-10, t)
        rows.append([t, st.cp0mass() - r_spec, st.hmass() - r_spec * t])
    header = [
        f"# cryoslosh vapour ideal-gas fixture for {stem}, generated by tools/coolprop_fixtures.py",
        *version_lines(fluid),
        f"# {N_IDEAL} rows uniform in sqrt(T) over [t_min_k - {IDEAL_T_BELOW_MIN} K, {IDEAL_T_MAX} K];",
        "# cv0 = CP0MASS - R_u/M, u0 = HMASS - (R_u/M) T at 1e-10 kg/m^3 (residual part negligible),",
        "# with R_u = 8.314462618 J/(mol K); u0 on CoolProp's reference state",
        "# units: t_k [K], cv0_j_kgk [J/(kg K)], u0_j_kg [J/kg]",
        f"# const fit_t_lo_k = {t_lo!r}",
        f"# const fit_t_hi_k = {IDEAL_T_MAX!r}",
    ]
    write(root / f"{stem}_ideal_gas.csv", header, ["t_k", "cv0_j_kgk", "u0_j_kg"], rows)

    p_crit = CP.PropsSI("pcrit", fluid)
    rows = []
    for p in CLOSED_TANK_P:
        if p >= 0.9 * p_crit:
            continue
        st.update(CP.PQ_INPUTS, p, 1.0)
        t_sat, h_sat = st.T(), st.hmass()
        for t in (1.5 * t_sat, *(t for t in WARM_GAS_T if t > 1.2 * t_sat)):
            st.update(CP.PT_INPUTS, p, t)
            rows.append([t, p, t_sat, st.hmass() - h_sat, st.rhomass()])
    header = [
        f"# cryoslosh warm-vapour fixture for {stem}, generated by tools/coolprop_fixtures.py",
        *version_lines(fluid),
        "# Enthalpy of the vapour at (T, P) above the saturated vapour at P: dh = H(T, P) - H(P, Q=1);",
        "# T = 1.5 T_sat(P) and those of 150, 300, 450, 600 K above 1.2 T_sat(P); P = 0.1, 0.6, 2 MPa",
        "# (below 0.9 P_crit)",
        "# units: t_k [K], p_pa [Pa], t_sat_k [K], dh_j_kg [J/kg], rho_kg_m3 [kg/m^3]",
    ]
    write(root / f"{stem}_warm_gas.csv", header, ["t_k", "p_pa", "t_sat_k", "dh_j_kg", "rho_kg_m3"], rows)


def closed_tank(root: Path, stem: str, fluid: str) -> None:
    """dP/du at constant mean density of a closed rigid tank in two-phase equilibrium."""
    st = CP.AbstractState("HEOS", fluid)
    p_crit = CP.PropsSI("pcrit", fluid)
    rows = []
    for p in CLOSED_TANK_P:
        if p >= 0.9 * p_crit:
            continue
        st.update(CP.PQ_INPUTS, p, 0.0)
        t, rho_l, u_l = st.T(), st.rhomass(), st.umass()
        st.update(CP.PQ_INPUTS, p, 1.0)
        rho_v, u_v = st.rhomass(), st.umass()
        for fill in CLOSED_TANK_FILL:
            rho = fill * rho_l + (1.0 - fill) * rho_v
            u = (fill * rho_l * u_l + (1.0 - fill) * rho_v * u_v) / rho
            st.update(CP.DmassUmass_INPUTS, rho, u + 1.0)
            p_up = st.p()
            st.update(CP.DmassUmass_INPUTS, rho, u - 1.0)
            p_down = st.p()
            rows.append([t, p, fill, rho, (p_up - p_down) / 2.0])
    header = [
        f"# cryoslosh closed-tank equilibrium fixture for {stem}, generated by tools/coolprop_fixtures.py",
        *version_lines(fluid),
        "# Two-phase equilibrium at pressure p_pa with liquid volume fraction fill; rho_mean = m / V.",
        "# dp_du: (dP/du) at constant rho_mean from CoolProp's (rho, u) flash at u +- 1 J/kg, so a",
        "# closed rigid tank heated at Q watts rises at dP/dt = dp_du * Q / m.",
        "# units: t_k [K], p_pa [Pa], fill [-], rho_mean_kg_m3 [kg/m^3], dp_du_pa_kg_j [Pa kg/J]",
    ]
    write(root / f"{stem}_closed_tank.csv", header, ["t_k", "p_pa", "fill", "rho_mean_kg_m3", "dp_du_pa_kg_j"], rows)


def gas(
    path: Path,
    stem: str,
    fluid: str,
    t_lo: float,
    t_hi: float,
    p: float,
    why: str,
    consts: list[tuple[str, float]],
) -> None:
    ts = np.exp(np.linspace(math.log(t_lo), math.log(t_hi), N_VAPOR))
    ts[0], ts[-1] = t_lo, t_hi
    rows = []
    for t in ts:
        t = float(t)
        phase = CP.PhaseSI("T", t, "P", p, fluid)
        if phase not in ("gas", "supercritical_gas", "supercritical"):
            raise SystemExit(f"{fluid}: not gaseous at T={t} K, P={p} Pa ({phase})")
        k = CP.PropsSI("L", "T", t, "P", p, fluid)
        mu = CP.PropsSI("V", "T", t, "P", p, fluid)
        rows.append([t, p, k, mu])
    header = [
        f"# cryoslosh gas-phase transport fixture for {stem}, generated by tools/coolprop_fixtures.py",
        *version_lines(fluid),
        f"# Single-phase gas at fixed pressure, {N_VAPOR} rows uniform in ln T over "
        f"[{t_lo!r}, {t_hi!r}] K; {why}",
        "# units: t_k [K], p_pa [Pa], k_w_mk [W/(m K)], mu_pa_s [Pa s]",
        *[f"# const {k} = {v!r}" for k, v in consts],
    ]
    write(path, header, ["t_k", "p_pa", "k_w_mk", "mu_pa_s"], rows)


def helium(root: Path) -> None:
    fluid = "Helium"
    m = CP.PropsSI("molar_mass", fluid)
    cp0, cv0 = ideal_gas_cp_cv(fluid, 300.0, m)
    gas(
        root / "GHe.csv",
        "GHe",
        fluid,
        HE_T_MIN,
        HE_T_MAX,
        HE_P,
        "1 bar (helium boils at 4.22 K at 1 bar)",
        [
            ("molar_mass_kg_per_mol", m),
            ("cp_j_per_kg_k", cp0),
            ("cv_j_per_kg_k", cv0),
            ("fit_t_min_k", HE_T_MIN),
            ("fit_t_max_k", HE_T_MAX),
            ("fit_p_pa", HE_P),
        ],
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    args = ap.parse_args()
    out = args.root / "tests" / "fixtures" / "fluids"
    out.mkdir(parents=True, exist_ok=True)
    for stem, fluid in PROPELLANTS:
        propellant(out, stem, fluid)
        vapor_eos(out, stem, fluid)
        closed_tank(out, stem, fluid)
        ideal_gas(out, stem, fluid)
    helium(out)


if __name__ == "__main__":
    main()
