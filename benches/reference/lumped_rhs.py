"""The lumped level's right-hand side of cryoslosh, ported once against an array namespace.

A same-work peer (issue 18): `model::evaluate` for `fidelity = "lumped"` — `derive::derive`
then `nodes::rhs` (src/model/{derive,nodes,boundary,thermal,slosh}.rs, src/fluids/*,
src/geometry.rs) — written over arrays of shape (n,), one element per instance, so that numpy
evaluates n instances per call and JAX can `jit` it (or `vmap` it: every function works on
scalars too). Branches are `where`; the Newton solves run each element until its own exit, as
the Rust lanes do (`Backend.loop`).

Every constant of the physics comes from the Parquet file written by
`examples/rhs_states.rs` (its `cryoslosh_constants` metadata: the propellant's fit
coefficients, helium, the vapour-energy offset, the slosh tables, the model floors); the only
numbers typed here are the published correlation constants that the Rust code has inline
(Churchill–Chu 0.825/0.387/0.492, McAdams 0.27, Lloyd–Moran 0.15, SP-106 4.98/0.318/1.84,
Miles 2.83/4.6, the Dacron factor is not needed: no insulation) and the solvers' iteration caps
and tolerances, each next to the Rust line it mirrors.

Not ported: `[insulation]` (the Lockheed MLI / foam leak solve, src/model/insulation.rs), the
`homogeneous` and `two_mode` levels. `make_rhs` refuses such inputs.
"""

import math

from fluid_tank import (
    ALT,
    Backend,
    E_ENV,
    E_OUT,
    E_PRESS,
    E_VENT,
    E_WD,
    E_WORK,
    E_WW,
    Fluid,
    H_B,
    H_S,
    M_B,
    M_G,
    M_S,
    M_V,
    NS,
    OUT,
    PI,
    PRESS_IN,
    P_FILT,
    Q1,
    Q1D,
    Tank,
    ULLAGE_NEWTON_MAX,
    ULLAGE_NEWTON_STEP_TOL,
    U_U,
    VEL,
    VENT_G,
    VENT_V,
)


class Model:
    """The right-hand side of one campaign's rows: structure (shape, optional systems, which
    closures are set) from the first row, every number per row, like `model::Group`."""

    def __init__(self, backend, constants, structure):
        self.b = b = Backend(backend) if isinstance(backend, str) else backend
        xp = b.xp
        k = constants
        if k["fidelity"] != "lumped":
            raise NotImplementedError("only the lumped level is ported")
        if structure["has_insulation"]:
            raise NotImplementedError("[insulation] is not ported")
        self.k = k
        self.st = structure
        self.fl = Fluid(b, k["fluid_props"])
        self.fl.rs = k["r_universal"] / k["fluid_props"]["molar_mass_kg_per_mol"]
        he = k["helium"]
        self.he = he
        self.he_r = k["r_universal"] / he["molar_mass_kg_per_mol"]
        self.off = k["vapor_energy_offset_j_per_kg"]
        t = k["slosh_table"]
        self.tab = {n: xp.asarray(t[n]) for n in ("bottom", "barrel", "top")}
        self.t = t

    # --- helpers ---------------------------------------------------------------------------

    def he_transport(self, t):
        xp, he = self.b.xp, self.he
        l = xp.log(xp.clip(t, 1.0, 10000.0) / he["t_ref_k"])
        return xp.exp(l * he["k_exp"]) * he["k_ref_w_per_m_k"], xp.exp(l * he["mu_exp"]) * he[
            "mu_ref_pa_s"
        ]

    def closure(self, p, name, correlation):
        if self.st[name]:
            return p[name]
        return correlation()

    # --- slosh (src/model/slosh.rs) ------------------------------------------------------

    def mode_shape(self, n, hr_raw):
        xp = self.b.xp
        xi = self.k["xi"][n]
        hr = xp.maximum(hr_raw, self.k["min_depth_ratio"])
        th = 1.0 - 2.0 / (xp.exp(hr * (2.0 * xi)) + 1.0)
        return dict(
            mass_ratio=th * 2.0 / (hr * (xi * (xi * xi - 1.0))),
            length_ratio=1.0 / (th * xi),
            omega2_ratio=th * xi,
        )

    def _cell(self, n, x):
        xp = self.b.xp
        x = xp.where(xp.isnan(x), 0.0, xp.clip(x, 0.0, float(n - 1)))
        i = xp.minimum(xp.floor(x), float(n - 2))
        return i.astype(int), x - i

    def _linear(self, n, x):
        i, t = self._cell(n, x)
        return [i, i + 1], [1.0 - t, t]

    def _catmull_rom(self, n, x):
        xp = self.b.xp
        i, t = self._cell(n, x)
        t2, t3 = t * t, t * t * t
        w0 = 0.5 * (-t3 + 2.0 * t2 - t)
        w1 = 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0)
        w2 = 0.5 * (-3.0 * t3 + 4.0 * t2 + t)
        w3 = 0.5 * (t3 - t2)
        idx = [xp.maximum(i - 1, 0), i, i + 1, xp.minimum(i + 2, n - 1)]
        first = i == 0
        w1, w2, w0 = (
            xp.where(first, w1 + 2.0 * w0, w1),
            xp.where(first, w2 - w0, w2),
            xp.where(first, 0.0, w0),
        )
        last = i + 2 > n - 1
        w2, w1, w3 = (
            xp.where(last, w2 + 2.0 * w3, w2),
            xp.where(last, w1 - w3, w1),
            xp.where(last, 0.0, w3),
        )
        return idx, [w0, w1, w2, w3]

    def _column(self, data, base, n, x):
        xp = self.b.xp
        idx, w = self._catmull_rom(n, x)
        out = [0.0 * x for _ in range(4)]
        for j, wj in zip(idx, w):
            for q in range(4):
                out[q] = out[q] + wj * xp.take(data, base + 4 * j + q)
        return out

    def domed_modes(self, k, l_over_r, z_over_r, v_over_r3):
        xp, t = self.b.xp, self.t
        kn, kw = self._linear(t["nk"], (xp.log2(k) - t["log2k_0"]) / t["log2k_step"])
        l = xp.maximum(l_over_r, 0.0)
        z = xp.maximum(z_over_r, 0.0)
        v = xp.maximum(v_over_r3, 1e-300)
        ns, nb, nt, nbeta = t["n_sigma"], t["n_barrel"], t["n_top"], t["n_beta"]
        # Bottom dome.
        xb = xp.sqrt(xp.maximum(z / k, 0.0)) * (ns - 1)
        q_bot = [0.0 * z] * 4
        for i, w in zip(kn, kw):
            c = self._column(self.tab["bottom"], 4 * i * ns, ns, xb)
            q_bot = [a + w * cc for a, cc in zip(q_bot, c)]
        # Barrel.
        xr = xp.sqrt(xp.maximum((z - k) / t["barrel_h_max"], 0.0)) * (nb - 1)
        q_bar = [0.0 * z] * 4
        for i, w in zip(kn, kw):
            c = self._column(self.tab["barrel"], 4 * i * nb, nb, xr)
            q_bar = [a + w * cc for a, cc in zip(q_bar, c)]
        # Top dome.
        u = xp.minimum((z - k - l) / k, 1.0)
        rs = xp.maximum(xp.sqrt(xp.maximum(1.0 - u * u, 0.0)), self.k["min_surface_radius_ratio"])
        xt = u / t["top_u_max"] * (nt - 1)
        beta = xp.exp(-2.0 * self.k["xi"][0] * l) * (nbeta - 1)
        bn, bw = self._linear(nbeta, beta)
        q_top = [0.0 * z] * 4
        for i, w in zip(kn, kw):
            for bb, wb in zip(bn, bw):
                base = 4 * nt * (bb + nbeta * i)
                c = self._column(self.tab["top"], base, nt, xt)
                q_top = [a + w * wb * cc for a, cc in zip(q_top, c)]
        m = rs * rs * rs / v
        in_bot = z <= k
        in_bar = z < k + l
        q = [xp.where(in_bot, a, xp.where(in_bar, bb, c)) for a, bb, c in zip(q_bot, q_bar, q_top)]
        one = 1.0 + 0.0 * z
        s_om = xp.where(in_bot, one, xp.where(in_bar, one, 1.0 / rs))
        s_m = xp.where(in_bot, one, xp.where(in_bar, 1.0 / v, m))
        modes = []
        for n in range(2):
            omega2 = q[2 * n] * s_om
            modes.append(
                dict(mass_ratio=q[2 * n + 1] * s_m, length_ratio=1.0 / omega2, omega2_ratio=omega2)
            )
        return modes

    def tank_modes(self, tank, level, v_liquid):
        if tank.shape == 0:
            r = tank.radius
            h = v_liquid / (r * r * PI)
            return [self.mode_shape(0, h / r), self.mode_shape(1, h / r)]
        r = tank.radius
        return self.domed_modes(tank.k, tank.length / r, level / r, v_liquid / (r * r * r))

    def wall_damping(self, nu, r, a_ax, h_over_r):
        xp = self.b.xp
        hr = xp.maximum(h_over_r, self.k["min_depth_ratio"])
        x = hr * 1.84
        e = xp.exp(x)
        inv = 1.0 / xp.exp(x)
        sinh, cosh = (e - inv) * 0.5, (e + inv) * 0.5
        shape = 0.318 / sinh * (((1.0 - hr) / cosh) + 1.0) + 1.0
        a = xp.maximum(a_ax, self.k["min_axial_accel"])
        return xp.sqrt(nu) * (4.98 / (2.0 * PI)) * shape / xp.sqrt(xp.sqrt(r * r * r * a))

    def baffle_damping(self, p, r, z_surface):
        xp = self.b.xp
        rings = self.st["max_baffle_count"]
        if rings == 0:
            return 0.0 * r
        width = p["baffle_width_m"]
        top, spacing = p["baffle_top_height_m"], p["baffle_spacing_m"]
        w = xp.minimum(width / r, 1.0)
        alpha = w * (2.0 - w)
        total = 0.0 * r
        for k in range(rings):
            z_ring = top - spacing * float(k)
            depth = z_surface - z_ring
            under = (depth >= 0.0) & (k < p["baffle_count"])
            total = total + xp.where(under, xp.exp(depth * -4.6 / r), 0.0)
        zeta = xp.sqrt(p["baffle_wave_amplitude_m"] / r) * 2.83 * total * alpha * xp.sqrt(alpha)
        none = (p["baffle_count"] == 0) | (width <= 0.0)
        return xp.where(none, 0.0, zeta)

    # --- derive (src/model/derive.rs) ----------------------------------------------------

    def derive(self, p, s, d):
        xp, fl, k = self.b.xp, self.fl, self.k
        x = {}
        m_s = xp.maximum(s[M_S], 1e-12)
        m_b = xp.maximum(s[M_B], 1e-12)
        x["t_layer"] = fl.t_from_h_l(s[H_S] / m_s)
        bulk_gone = s[M_B] <= 0.0
        h_bulk = xp.where(bulk_gone, s[H_S] / m_s, s[H_B] / m_b)
        x["t_bulk"] = xp.where(bulk_gone, x["t_layer"], fl.t_from_h_l(h_bulk))
        x["rho_layer"] = fl.rho_l(x["t_layer"])
        x["rho_bulk"] = fl.rho_l(x["t_bulk"])
        x["v_layer"] = s[M_S] / x["rho_layer"]
        x["v_bulk"] = s[M_B] / x["rho_bulk"]
        x["m_liquid"] = s[M_S] + s[M_B]
        v_l = x["v_layer"] + x["v_bulk"]
        tank = self.tank
        # fill_level
        z = tank.liquid_height(v_l)
        x["level"] = z
        floor = 1.0e-6 * p["tank_radius_m"] ** 2
        x["interface_area"] = xp.maximum(tank.interface_area(z), floor)
        wall = tank.wall_area
        raw = tank.wetted_area(z) / wall
        mws = k["min_wall_share"]
        clamped = (raw <= mws) | (raw >= 1.0 - mws)
        slope = tank.wetted_area_slope(z) / wall
        x["wetted_share"] = xp.where(clamped, xp.clip(raw, mws, 1.0 - mws), raw)
        x["wetted_share_slope"] = xp.where(clamped, 0.0, slope)
        nu = fl.mu_l(x["t_bulk"]) / x["rho_bulk"]
        # motion
        m_tank = x["m_liquid"] + s[M_V] + s[M_G]
        frac = p["feed_propellant_fraction"]
        other_used = s[OUT] * (1.0 / frac - 1.0)
        mass = xp.maximum(p["vehicle_dry_mass_kg"] + m_tank - other_used, 1.0)
        v = s[VEL]
        rho_air = xp.exp(-xp.maximum(s[ALT], 0.0) / k["scale_height_m"]) * k["rho_sea_level"]
        drag = rho_air * 0.5 * v * xp.abs(v) * p["vehicle_drag_area_m2"]
        a = xp.where(d["d_flying"], (d["d_thrust_n"] - drag) / mass, 0.0)
        a_ax = xp.maximum(a + d["d_gravity_m_s2"] + d["d_a_ax_extra"], k["min_axial_accel"])
        x["vehicle_mass"], x["drag"], x["a_ax"] = mass, drag, a_ax
        a_total = xp.sqrt(a_ax * a_ax + d["d_a_lat"] * d["d_a_lat"])
        # slosh_params
        radius = p["tank_radius_m"]
        r_eq = xp.maximum(tank.surface_radius(z), radius * k["min_surface_radius_ratio"])
        h_eq = v_l / (r_eq * r_eq * PI)
        zeta = (
            self.wall_damping(nu, r_eq, a_total, h_eq / r_eq)
            + self.baffle_damping(p, r_eq, z)
            + p["extra_damping"]
        )
        modes = self.tank_modes(tank, z, v_l)
        x["slosh_mass"] = [m["mass_ratio"] * x["m_liquid"] for m in modes]
        x["slosh_length"] = [m["length_ratio"] * radius for m in modes]
        x["slosh_omega"] = [xp.sqrt(m["omega2_ratio"] * a_total / radius) for m in modes]
        x["slosh_zeta"] = [zeta, zeta]
        angle = s[Q1]
        x["v_ullage"] = tank.volume - v_l + p["coupling_volume_m3"] * xp.sin(angle)
        rho_v = s[M_V] / x["v_ullage"]
        t_u, vapor = self.ullage_temperature(s[M_V], s[M_G], s[U_U], rho_v)
        x["t_ullage"] = t_u
        x["m_vapor"] = s[M_V]
        x["p_vapor"] = vapor["p"]
        x["p_ullage"] = x["p_vapor"] + s[M_G] * self.he_r * t_u / x["v_ullage"]
        mc = p["wall_areal_mass_kg_per_m2"] * tank.wall_area * p["wall_cp_j_per_kg_k"]
        wet = x["wetted_share"]
        x["t_wall_dry"] = s[E_WD] / (mc * (1.0 - wet))
        x["t_wall_wet"] = s[E_WW] / (mc * wet)
        return x

    def ullage_temperature(self, m_v, m_g, u_j, rho_v):
        xp, fl = self.b.xp, self.fl
        f = fl.f
        t_r = 0.5 * (f["t_min_k"] + f["t_max_k"])
        u_r, cv_r = fl.vapor_ideal(t_r + 0.0 * m_v)
        cv_g = m_g * self.he["cv_j_per_kg_k"]
        t = (u_j - m_v * (self.off + u_r - cv_r * t_r)) / (m_v * cv_r + cv_g)

        def body(c):
            t, done = c
            v = fl.vapor_state(t, rho_v)
            u0, cv0 = fl.vapor_ideal(t)
            r = m_v * (u0 + self.off + v["u_res"]) + cv_g * t - u_j
            step = r / (m_v * (cv0 + v["du_res_dt"]) + cv_g)
            t = xp.where(done, t, t - step)
            done = done | (xp.abs(step) <= xp.abs(t) * ULLAGE_NEWTON_STEP_TOL) | xp.isnan(step)
            return t, done

        t, _ = self.b.loop(ULLAGE_NEWTON_MAX, body, (t, xp.zeros_like(t, dtype=bool)), lambda c: c[1])
        return t, fl.vapor_state(t, rho_v)

    # --- thermal closures (src/model/thermal.rs) -----------------------------------------

    def rayleigh(self, pr, accel, dt_k, length):
        # thermal::rayleigh: ν = μ/ρ and α = k/(ρ c_p) substituted (one divide).
        xp = self.b.xp
        l3 = length * length * length
        drive = xp.maximum(accel, 0.0) * xp.abs(pr["beta"]) * xp.abs(dt_k) * l3
        inv_mu_k = 1.0 / (pr["mu"] * pr["k"])
        ra = drive * (pr["rho"] * pr["rho"] * pr["cp"]) * inv_mu_k
        return ra, pr["mu"] * pr["mu"] * pr["cp"] * inv_mu_k

    def h_vertical_wall(self, pr, accel, dt_k, length_m):
        # thermal::h_vertical_wall: the powers in logarithms (three log, two exp).
        xp = self.b.xp
        length = xp.maximum(length_m, 1.0e-3)
        ra, prn = self.rayleigh(pr, accel, dt_k, length)
        pr_term = xp.exp((math.log(0.492) - xp.log(prn)) * (9.0 / 16.0))
        with with_errstate(xp):
            ln_core = xp.log(ra) * (1.0 / 6.0) - xp.log(pr_term + 1.0) * (8.0 / 27.0)
        nu = xp.exp(ln_core) * 0.387 + 0.825
        return nu * nu * pr["k"] / length

    def h_stable_interface(self, pr, accel, dt_k, length_m):
        xp = self.b.xp
        length = xp.maximum(length_m, 1.0e-3)
        ra, _ = self.rayleigh(pr, accel, dt_k, length)
        return (xp.sqrt(xp.sqrt(ra)) * 0.27 + 1.0) * pr["k"] / length

    def h_unstable_interface(self, pr, accel, dt_unstable, length_m):
        xp = self.b.xp
        length = xp.maximum(length_m, 1.0e-3)
        ra, _ = self.rayleigh(pr, accel, xp.maximum(dt_unstable, 0.0), length)
        with with_errstate(xp):
            out = xp.exp(xp.log(ra) * (1.0 / 3.0)) * 0.15 * pr["k"] / length
        return out

    def stiff_blend(self, z):
        xp = self.b.xp
        big = z > 1.0
        with with_errstate(xp):
            v = xp.where(big, 1.0 / z, z)
        s_lo = 1.0 + 0.0 * z
        v_lo = 1.0 + 0.0 * z
        for _ in range(1, self.k["stiff_blend_order"]):
            s_lo = s_lo * v + 1.0
            v_lo = v_lo * v
        s_hi = s_lo + v_lo * v
        inv_s_hi = 1.0 / s_hi
        a = s_lo * inv_s_hi * xp.where(big, v, 1.0)
        w = xp.where(big, v, v_lo) * inv_s_hi
        return a, w

    def wall_exchange(self, ua, dt, c_wall, c_fluid, dtemp, forcing):
        z = dt * ua * ((c_wall + c_fluid) / (c_wall * c_fluid))
        a, w = self.stiff_blend(z)
        return ua * (a * dtemp + w * dt * forcing)

    def orifice_flow(self, area, p_up, p_down, t_k, r, gamma):
        xp = self.b.xp
        g = gamma
        pr_crit = xp.power(2.0 / (g + 1.0), g / (g - 1.0))
        prr = xp.maximum(p_down / p_up, pr_crit)
        flux = xp.sqrt(
            xp.maximum(
                g * 2.0 / ((g - 1.0) * r * t_k) * (xp.power(prr, 2.0 / g) - xp.power(prr, (g + 1.0) / g)),
                0.0,
            )
        )
        closed = (p_up <= p_down) | (p_up <= 0.0)
        return xp.where(closed, 0.0, area * p_up * flux)

    # --- nodes::rhs (src/model/nodes.rs, boundary.rs) ------------------------------------

    def rhs(self, p, d, dt, s):
        """`_rhs` with numpy's warnings off: like the Rust lanes, the port evaluates branches it
        then selects away (asinh(x)/x at x = 0 in a sphere's zone area, log 0 in a zero
        Rayleigh number)."""
        with with_errstate(self.b.xp):
            return self._rhs(p, d, dt, s)

    def _rhs(self, p, d, dt, s):
        """Rates (a list of NS arrays) at states `s` (list of NS arrays) under drives `d` and
        parameters `p` (dicts of arrays, the Parquet columns without their prefix)."""
        xp, fl, k, st = self.b.xp, self.fl, self.k, self.st
        self.tank = Tank(self.b, st["shape"], p["tank_radius_m"], p["tank_length_m"], p["tank_dome_ratio"])
        tank = self.tank
        x = self.derive(p, s, d)
        zero = 0.0 * s[M_V]
        ds = [zero] * NS
        off = self.off
        t_u, t_s, t_b = x["t_ullage"], x["t_layer"], x["t_bulk"]
        rho_v = s[M_V] / x["v_ullage"]
        vapor = fl.vapor_state(t_u, rho_v)
        rv = fl.rs
        u0, cv0 = fl.vapor_ideal(t_u)
        u_vap = u0 + off + vapor["u_res"]
        cv_g = self.he["cv_j_per_kg_k"]
        cp_he = self.he["cp_j_per_kg_k"]
        heat_cap = s[M_V] * (vapor["du_res_dt"] + cv0) + s[M_G] * cv_g
        a_i = x["interface_area"]
        r_surf = xp.maximum(tank.surface_radius(x["level"]), 1.0e-3)
        a_tot = tank.wall_area
        dry_share = 1.0 - x["wetted_share"]
        a_wet, a_dry = a_tot * x["wetted_share"], a_tot * dry_share
        speed = xp.abs(s[Q1D])
        enhancement = p["h_enhancement"]

        def fits(t, rho):
            return dict(t=t, rho=rho, cp=fl.cp_l(t), dh_dt=fl.dh_l_dt(t), drho_dt=fl.drho_l_dt(t), h=fl.h_l(t))

        def convection(n):
            return dict(k=fl.k_l(n["t"]), mu=fl.mu_l(n["t"]), rho=n["rho"], cp=n["cp"], beta=-n["drho_dt"] / n["rho"])

        bulk, layer = fits(t_b, x["rho_bulk"]), fits(t_s, x["rho_layer"])
        liq = convection(bulk)
        # gas_props
        m = x["m_vapor"] + s[M_G]
        y = xp.where(m > 0.0, x["m_vapor"] / m, 1.0)
        k_v, mu_v = fl.vapor_transport(t_u)
        k_g, mu_g = self.he_transport(t_u)
        he = 1.0 - y
        gas = dict(
            k=y * k_v + he * k_g,
            mu=y * mu_v + he * mu_g,
            rho=m / x["v_ullage"],
            cp=y * (cv0 + rv) + he * cp_he,
            beta=1.0 / t_u,
        )
        h_wl = self.closure(
            p, "h_wall_liquid", lambda: self.h_vertical_wall(liq, x["a_ax"], x["t_wall_wet"] - t_b, x["level"])
        )
        h_wu = self.closure(
            p,
            "h_wall_ullage",
            lambda: self.h_vertical_wall(gas, x["a_ax"], x["t_wall_dry"] - t_u, tank.height - x["level"]),
        )
        c_wall = p["wall_areal_mass_kg_per_m2"] * tank.wall_area * p["wall_cp_j_per_kg_k"]
        bulk_gone = s[M_B] <= 0.0
        c_bulk = xp.maximum(xp.where(bulk_gone, s[M_S], s[M_B]), 1.0e-9) * liq["cp"]
        # insulation::wall_heat without [insulation]
        q_env = p["heat_leak_w"]
        warming = q_env / c_wall
        env = dict(
            dry_w=q_env * dry_share,
            wet_w=q_env * x["wetted_share"],
            total_w=q_env + zero,
            warming_dry=warming,
            warming_wet=warming,
        )
        q_wl = self.wall_exchange(
            h_wl * a_wet, dt, c_wall * x["wetted_share"], c_bulk, x["t_wall_wet"] - t_b, env["warming_wet"]
        )
        depth = x["v_layer"] / a_i
        a_below = tank.wetted_area(x["level"] - depth)
        a_ws = xp.minimum(xp.maximum(a_wet - a_below, 0.0), a_wet)
        contact = a_ws / xp.maximum(a_wet, 1.0e-12)
        lift = p["wall_heat_to_layer"]
        to_layer = xp.where(bulk_gone, 1.0, contact + lift * (1.0 - contact))
        q_ws, q_wb = to_layer * q_wl, (1.0 - to_layer) * q_wl
        q_wu = self.wall_exchange(
            h_wu * a_dry, dt, c_wall * dry_share, heat_cap, x["t_wall_dry"] - t_u, env["warming_dry"]
        )
        h_us = (
            self.closure(p, "h_us", lambda: self.h_stable_interface(gas, x["a_ax"], t_u - t_s, r_surf * 0.5))
            + enhancement * speed
        )
        # nodes::rhs: the ullage-layer exchange takes the step average of stiff_blend.
        z_us = dt * h_us * a_i * (1.0 / heat_cap + 1.0 / (xp.maximum(s[M_S], 1.0e-9) * layer["cp"]))
        q_us = self.stiff_blend(z_us)[0] * h_us * a_i * (t_u - t_s)
        h_sb = (
            self.closure(p, "h_sb", lambda: zero)
            + self.h_unstable_interface(liq, x["a_ax"], t_b - t_s, r_surf * 0.5)
            + enhancement * speed
        )
        q_sb = h_sb * a_i * (t_s - t_b)
        delta = xp.maximum(s[M_S] / (x["rho_layer"] * a_i), 1.0e-6)
        # wave_mixing: the wave's eddy diffusivity at the layer's base joins the penetration growth.
        l1 = x["slosh_length"][0]
        waves = p["mixing"] * xp.abs(l1 * s[Q1]) * xp.abs(l1 * s[Q1D])
        eddy = waves * xp.exp(delta * (k["xi"][0] / p["tank_radius_m"]) * -2.0)
        alpha = p["diffusivity_factor"] * fl.k_l(t_s) / (x["rho_layer"] * layer["cp"]) + eddy
        bulk_left = xp.clip(s[M_B] / ((s[M_B] + s[M_S]) * k["bulk_merge_fraction"] + 1.0e-9), 0.0, 1.0)
        m_strat = x["rho_layer"] * a_i * PI * alpha / (delta * 8.0) * bulk_left
        # nodes::rhs: the layer-bulk exchange (Q_sb; no jet mixer or TVS spray in this port) as a
        # two-node relaxation.
        m_b = xp.maximum(s[M_B], 0.0)
        z_x = dt * (h_sb * a_i / liq["cp"]) * (
            1.0 / xp.maximum(s[M_S], 1.0e-9) + 1.0 / xp.maximum(m_b, 1.0e-9)
        )
        damp = self.stiff_blend(z_x)[0]
        q_sb = damp * q_sb

        b = self.boundary_flows(p, s, d, x)
        h_mass = h_us / (gas["rho"] * gas["cp"])
        h_fg = fl.h_fg(t_s)
        k_evap, dp = self.evaporation_driving(p, s, x, h_mass)
        out_b, out_s = b["out"] * bulk_left, b["out"] * (1.0 - bulk_left)
        h_ls, h_lb = layer["h"], bulk["h"]
        h_vap_gas = u_vap + vapor["z"] * rv * t_u
        y = b["y_vapor"]
        h_u = y * h_vap_gas + (1.0 - y) * cp_he * t_u
        h_press = self.pressurant_inlet_enthalpy(p, x["p_ullage"])
        share = p["pressurant_vapor_share"] if st["has_pressurization"] else zero
        press_v = b["press"] * share
        pu = x["p_ullage"]
        # Liquid leaving a node for good carries its enthalpy plus the flow work P/rho.
        hf_s, hf_b = h_ls + pu / layer["rho"], h_lb + pu / bulk["rho"]

        ds[M_G] = b["press"] - press_v - b["vent"] * (1.0 - y)
        ds[M_B] = -m_strat - out_b
        f_b = q_wb + q_sb - m_strat * hf_b - out_b * hf_b
        dh_b, dv_b = liquid_node_rates(pu, f_b, ds[M_B], bulk)
        ds[H_B] = dh_b
        self.motion_rates(p, s, d, x, ds)
        c_v = p["coupling_volume_m3"]
        dv_slosh = c_v * xp.cos(s[Q1]) * s[Q1D]

        def tail(mm):
            e_evap = xp.maximum(mm, 0.0) * (h_ls + h_fg) + xp.minimum(mm, 0.0) * h_vap_gas
            dm_v = mm + press_v - b["vent"] * y
            dm_s = -mm + m_strat - out_s
            f_s = q_ws + q_us - q_sb - e_evap + m_strat * hf_b - out_s * hf_s
            dh_s, dv_s = liquid_node_rates(pu, f_s, dm_s, layer)
            du_u = (
                q_wu - q_us + e_evap + b["press"] * h_press - b["vent"] * h_u + pu * (dv_s + dv_b) - pu * dv_slosh
            )
            return [dm_v, dm_s, dh_s, du_u, dv_s]

        dpsat_dt = fl.psat_and_slope(t_s)[1]
        dm_g = ds[M_G]

        def dp_rate(r):
            dt_s = (r[2] - h_ls * r[1]) / (xp.maximum(s[M_S], 1.0e-9) * layer["dh_dt"])
            dv_u = dv_slosh - r[4] - dv_b
            drho = (r[0] - rho_v * dv_u) / x["v_ullage"]
            dt_u = (r[3] - r[0] * u_vap - s[M_V] * vapor["du_res_drho"] * drho - dm_g * cv_g * t_u) / heat_cap
            dp_v = vapor["dp_dt"] * dt_u + vapor["dp_drho"] * drho
            return dpsat_dt * dt_s - dp_v

        forcing = dp_rate(tail(zero))
        j_evap = xp.maximum(forcing - dp_rate(tail(zero + 1.0)), 0.0)
        j_cond = xp.maximum(dp_rate(tail(zero - 1.0)) - forcing, 0.0)

        def rate(j):
            a, w = self.stiff_blend(dt * k_evap * j)
            return k_evap * (a * dp + w * dt * forcing)

        m_evap = xp.maximum(rate(j_evap), 0.0) + xp.minimum(rate(j_cond), 0.0)
        dm_v, dm_s, dh_s, du_u, dv_s = tail(m_evap)
        ds[M_V], ds[M_S], ds[H_S], ds[U_U] = dm_v, dm_s, dh_s, du_u
        # wall_rates
        section = tank.interface_area(x["level"])
        dz = (dv_s + dv_b) / xp.maximum(section, 1.0e-9)
        m_wall = p["wall_areal_mass_kg_per_m2"] * tank.wall_area
        dshare = x["wetted_share_slope"] * dz
        t_moving = xp.where(dshare < 0.0, x["t_wall_wet"], x["t_wall_dry"])
        handover = m_wall * dshare * p["wall_cp_j_per_kg_k"] * t_moving
        ds[E_WD] = env["dry_w"] - q_wu - handover
        ds[E_WW] = env["wet_w"] - q_wl + handover
        ds[E_ENV] = env["total_w"]
        # boundary_ledger
        ds[VENT_V] = b["vent"] * b["y_vapor"]
        ds[VENT_G] = b["vent"] * (1.0 - b["y_vapor"])
        ds[OUT] = b["out"]
        ds[PRESS_IN] = b["press"]
        ds[E_PRESS] = b["press"] * h_press
        ds[E_VENT] = b["vent"] * h_u
        ds[E_OUT] = out_s * hf_s + out_b * hf_b
        ds[E_WORK] = -pu * dv_slosh
        return ds

    def evaporation_driving(self, p, s, x, h_mass):
        xp, fl = self.b.xp, self.fl
        t_s = x["t_layer"]
        rv = fl.rs
        mol_v = fl.f["molar_mass_kg_per_mol"]

        def schrage():
            sig = p["accommodation"]
            return (
                x["interface_area"]
                * 2.0
                * sig
                / (2.0 - sig)
                * xp.sqrt(mol_v / (t_s * (2.0 * PI * self.k["r_universal"])))
            )

        k_kin = self.closure(p, "evaporation_coefficient", schrage)
        moles_v = s[M_V] / mol_v
        moles_g = s[M_G] / self.he["molar_mass_kg_per_mol"]
        x_he = moles_g / xp.maximum(moles_v + moles_g, 1.0e-300)
        diffusion = x_he * rv * x["t_ullage"] / xp.maximum(h_mass * x["interface_area"], 1.0e-300)
        kk = 1.0 / (1.0 / k_kin + diffusion)
        return kk, fl.psat_and_slope(t_s)[0] - x["p_vapor"]

    def boundary_flows(self, p, s, d, x):
        xp, fl, k, st = self.b.xp, self.fl, self.k, self.st
        zero = 0.0 * s[M_V]
        m_u = s[M_V] + s[M_G]
        y_v = xp.where(m_u > 0.0, s[M_V] / m_u, 1.0)
        out = dict(y_vapor=y_v, press=zero, vent=zero, out=zero)
        if st["has_pressurization"]:
            e = p["press_setpoint_pa"] - x["p_ullage"]
            e_dot = -(x["p_ullage"] - s[P_FILT]) / p["press_filter_s"]
            pd = p["press_kp"] * e + p["press_kd"] * e_dot
            # Gain schedule: both gains times V_u / V_ref where V_ref > 0 (files written before
            # the key have no column: fixed gains).
            v_ref = p.get("press_schedule_ref_m3", 0.0 * pd)
            on = v_ref > 0.0
            pd = pd * xp.where(on, x["v_ullage"] / xp.where(on, v_ref, 1.0), 1.0)
            demand = xp.minimum(xp.maximum(pd, 0.0), p["press_max_flow"])
            bottle = p["press_bottle_kg"]
            left = bottle - s[PRESS_IN]
            fade = xp.clip(left / (bottle * 1.0e-3 + 1.0e-9), 0.0, 1.0)
            out["press"] = xp.where(d["d_pressurize"], demand * fade, 0.0)
        if st["has_relief"]:
            rv = fl.rs
            rg = self.he_r
            vap = 1.0 - y_v
            r_mix = y_v * rv + vap * rg
            cv_v = fl.vapor_ideal(x["t_ullage"])[1]
            cp = y_v * (cv_v + rv) + vap * self.he["cp_j_per_kg_k"]
            cv = y_v * cv_v + vap * self.he["cv_j_per_kg_k"]
            back = xp.exp(-xp.maximum(s[ALT], 0.0) / k["scale_height_m"]) * k["p_sea_level_pa"]
            with with_errstate(xp):
                vent = self.orifice_flow(p["relief_flow_area_m2"], x["p_ullage"], back, x["t_ullage"], r_mix, cp / cv)
            out["vent"] = xp.where(d["d_valve_open"], vent, 0.0)
        engine = d["d_thrust_n"] / (p["feed_isp_s"] * k["g0"])
        m_l = x["m_liquid"]
        avail = xp.clip(m_l / (xp.maximum(m_l, 1.0) * 1.0e-6 + 1.0e-3), 0.0, 1.0)
        out["out"] = xp.where(d["d_burning"], engine * p["feed_propellant_fraction"] * avail, 0.0)
        return out

    def motion_rates(self, p, s, d, x, ds):
        xp, k = self.b.xp, self.k
        th, w = s[Q1], s[Q1D]
        l, om, ze = x["slosh_length"][0], x["slosh_omega"][0], x["slosh_zeta"][0]
        sin, cos = xp.sin(th), xp.cos(th)
        acc = -(x["a_ax"] / l) * sin - ze * 2.0 * om * w - (d["d_a_lat"] / l) * cos
        ds[Q1] = w
        ds[Q1D] = acc
        r = (xp.maximum(s[ALT], 0.0) + k["earth_radius_m"]) / k["earth_radius_m"]
        r = 1.0 / r
        gravity = r * r * k["g0"]
        sin_gamma = xp.sin(d["d_gamma_rad"])
        dv = (d["d_thrust_n"] - x["drag"]) / x["vehicle_mass"] - gravity * sin_gamma
        ds[VEL] = xp.where(d["d_flying"], dv, ds[VEL])
        ds[ALT] = xp.where(d["d_flying"], s[VEL] * sin_gamma, ds[ALT])
        if self.st["has_pressurization"]:
            ds[P_FILT] = (x["p_ullage"] - s[P_FILT]) / p["press_filter_s"]

    def pressurant_inlet_enthalpy(self, p, p_ullage):
        xp, fl = self.b.xp, self.fl
        if not self.st["has_pressurization"]:
            return 0.0 * p_ullage
        t_in = p["press_gas_temperature_k"]
        helium = t_in * self.he["cp_j_per_kg_k"]
        if not self.st["autogenous"]:
            return helium + 0.0 * p_ullage
        u0, _ = fl.vapor_ideal(t_in)
        h_res = fl.vapor_h_res_at_tp(t_in, p_ullage)
        vapour = u0 + t_in * fl.rs + self.off + h_res
        return xp.where(p["pressurant_vapor_share"] > 0.0, vapour, helium)


def liquid_node_rates(p_pa, flux_w, dm, n):
    rho, h = n["rho"], n["h"]
    q = 1.0 / (rho * rho * n["dh_dt"])
    beta = -n["drho_dt"] * q
    inv_rho = rho * n["dh_dt"] * q
    dh = (flux_w - p_pa * dm * inv_rho + p_pa * beta * h * dm) / (p_pa * beta + 1.0)
    return dh, dm * inv_rho + beta * (dh - h * dm)


class with_errstate:
    """numpy: silence the warnings of log(0) and 1/0 that the Rust code also evaluates (and
    then selects away); a no-op for JAX."""

    def __init__(self, xp):
        self.ctx = xp.errstate(all="ignore") if hasattr(xp, "errstate") else None

    def __enter__(self):
        if self.ctx is not None:
            self.ctx.__enter__()

    def __exit__(self, *a):
        if self.ctx is not None:
            self.ctx.__exit__(*a)


# --- reading the rows --------------------------------------------------------------------


def load(path):
    """The rows and constants of a file from `examples/rhs_states.rs`: (constants, structure,
    columns as numpy arrays)."""
    import json

    import numpy as np
    import pyarrow.parquet as pq

    f = pq.ParquetFile(path)
    meta = f.metadata.metadata or {}
    constants = json.loads(meta[b"cryoslosh_constants"])
    t = f.read()
    cols = {n: np.asarray(t.column(n).to_numpy(), dtype=np.float64) for n in t.column_names}
    first = {n: v[0] for n, v in cols.items()}
    structure = dict(
        shape=int(first["p_tank_shape"]),
        has_pressurization=bool(first["p_has_pressurization"]),
        autogenous=bool(first["p_pressurant_vapor_share"] > 0.0),
        has_relief=bool(first["p_has_relief"]),
        has_insulation=bool(first["p_has_insulation"]),
        max_baffle_count=int(cols["p_baffle_count"].max()),
        evaporation_coefficient=not np.isnan(first["p_evaporation_coefficient"]),
        h_us=not np.isnan(first["p_h_us"]),
        h_sb=not np.isnan(first["p_h_sb"]),
        h_wall_ullage=not np.isnan(first["p_h_wall_ullage"]),
        h_wall_liquid=not np.isnan(first["p_h_wall_liquid"]),
    )
    return constants, structure, cols


def split(cols, xp=None, dtype=None):
    """(p, d, dt, s, rates) from the columns: `p` without its `p_` prefix, drive flags as
    booleans."""
    import numpy as np

    conv = (lambda a: a) if xp is None else xp.asarray
    p = {n[2:]: conv(v) for n, v in cols.items() if n.startswith("p_")}
    d = {}
    for n, v in cols.items():
        if n.startswith("d_"):
            flag = n in ("d_burning", "d_flying", "d_pressurize", "d_valve_open", "d_space")
            d[n] = conv(v != 0.0) if flag else conv(v)
    s = [conv(cols[f"s_{k}"]) for k in range(NS)]
    r = np.stack([cols[f"r_{k}"] for k in range(NS)], axis=1)
    return p, d, conv(cols["dt"]), s, r
