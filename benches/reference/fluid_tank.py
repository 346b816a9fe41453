"""Propellant fits and tank geometry of the lumped right-hand side's port (`lumped_rhs.py`),
written against an array namespace: `fluids::FluidProps` (liquid fits, saturation, the real-gas
vapour, T(h_l)), `geometry::TankLanes` (level, surface, wetted areas, the dome cap solve) and the
state slots and solver caps of the Rust code. Every fit coefficient comes from the engine through
the Parquet file's metadata; see `lumped_rhs.py`.
"""

import math

PI = math.pi

# State slots (src/model/state.rs).
M_V, M_G, U_U, M_S, H_S, M_B, H_B, E_WD, E_WW, Q1, Q1D, Q2, Q2D, VEL, ALT, P_FILT = range(16)
VENT_V, VENT_G, OUT, PRESS_IN, E_ENV, E_PRESS, E_VENT, E_OUT, E_WORK, E_PUMP, VENT_TVS = range(16, 27)
NS = 27  # E_PUMP (the jet mixer's heat) and VENT_TVS stay 0 here: the port has no [mixer] or [tvs]
# The slots' names in order, for reports (`check.py`).
SLOT_NAMES = (
    "M_V", "M_G", "U_U", "M_S", "H_S", "M_B", "H_B", "E_WD", "E_WW", "Q1", "Q1D", "Q2", "Q2D",
    "VEL", "ALT", "P_FILT", "VENT_V", "VENT_G", "OUT", "PRESS_IN", "E_ENV", "E_PRESS", "E_VENT",
    "E_OUT", "E_WORK", "E_PUMP", "VENT_TVS",
)
assert [globals()[n] for n in SLOT_NAMES] == list(range(NS))

# Solver caps and tolerances, private constants of the Rust code.
FLUID_MAX_ITER = 40  # fluids/mod.rs MAX_ITER
T_FROM_H_TOL = 1e-12  # fluids/mod.rs T_FROM_H_TOL
ULLAGE_NEWTON_MAX = 16  # model/derive.rs
ULLAGE_NEWTON_STEP_TOL = 1e-7  # model/derive.rs
CAP_MAX_ROUNDS = 100  # geometry.rs cap_fraction
CAP_START_SPLIT = 0.8  # geometry.rs CAP_START_SPLIT
SERIES_LIMIT = 1e-2  # geometry.rs
F64_EPS = 2.220446049250313e-16


class Backend:
    """The array namespace and the two control-flow forms the port needs."""

    def __init__(self, name):
        self.name = name
        if name == "numpy":
            import numpy as xp

            self.xp = xp
        elif name == "jax":
            import jax

            jax.config.update("jax_enable_x64", True)
            import jax.numpy as xp

            self.xp = xp
            self.lax = jax.lax
        else:
            raise ValueError(name)

    def where(self, m, a, b):
        return self.xp.where(m, a, b)

    def loop(self, n, body, carry, done_of):
        """Up to `n` rounds of `carry = body(carry)`, stopping once `done_of(carry)` is all
        true (each element stops moving on its own inside `body`)."""
        if self.name == "numpy":
            for _ in range(n):
                if bool(self.xp.all(done_of(carry))):
                    break
                carry = body(carry)
            return carry
        lax = self.lax

        def cond(c):
            i, inner = c
            return (i < n) & ~self.xp.all(done_of(inner))

        def step(c):
            i, inner = c
            return i + 1, body(inner)

        return lax.while_loop(cond, step, (0, carry))[1]


def poly(c, x):
    acc = 0.0 * x
    for a in reversed(c):
        acc = acc * x + a
    return acc


def poly_deriv(c, x):
    acc = 0.0 * x
    for i in range(len(c) - 1, 0, -1):
        acc = acc * x + i * c[i]
    return acc


RECIPROCALS = [1.0, 1.0 / 2.0, 1.0 / 3.0, 1.0 / 4.0, 1.0 / 5.0, 1.0 / 6.0, 1.0 / 7.0, 1.0 / 8.0]


def poly_integral(c, x):
    acc = 0.0 * x
    for i in range(len(c) - 1, -1, -1):
        acc = acc * x + c[i] * RECIPROCALS[i]
    return acc * x


def poly_f(c, x):
    """`poly` on a Python float (the Rust code's f64 constants such as poly(c, −1))."""
    acc = 0.0
    for a in reversed(c):
        acc = acc * x + a
    return acc


def poly_integral_f(c, x):
    acc = 0.0
    for i in range(len(c) - 1, -1, -1):
        acc = acc * x + c[i] * RECIPROCALS[i]
    return acc * x


class Fluid:
    """`FluidProps` (src/fluids/mod.rs, vapor.rs) of one propellant."""

    def __init__(self, b, f):
        self.b, self.xp, self.f = b, b.xp, f
        self.t_min, self.t_max = f["t_min_k"], f["t_max_k"]
        self.t_mid = 0.5 * (self.t_min + self.t_max)
        self.t_half = 0.5 * (self.t_max - self.t_min)
        self.inv_t_half = 1.0 / self.t_half
        self.rs = None  # set by Model (needs R_UNIVERSAL)
        dh = f["dh_l_sat"]
        self.base = poly_integral_f(dh, -1.0)
        self.h_max = (poly_integral_f(dh, 1.0) - self.base) * self.t_half
        self.cp_lo, self.cp_hi = poly_f(dh, -1.0), poly_f(dh, 1.0)

    def x_of(self, t):
        return (t - self.t_mid) / self.t_half

    def xc(self, t):
        return self.xp.clip(self.x_of(t), -1.0, 1.0)

    def t_of(self, x):
        return x * self.t_half + self.t_mid

    def psat_and_slope(self, t):
        xp = self.xp
        x = self.x_of(t)
        xc = xp.clip(x, -1.0, 1.0)
        s = poly_deriv(self.f["ln_psat"], xc)
        ln_p = poly(self.f["ln_psat"], xc) + s * (x - xc)
        p = xp.exp(xp.clip(ln_p, -700.0, 700.0))
        limited = xp.abs(ln_p) > 700.0
        return p, xp.where(limited, 0.0, p * s * self.inv_t_half)

    def rho_l(self, t):
        return poly(self.f["rho_l"], self.xc(t))

    def drho_l_dt(self, t):
        x = self.x_of(t)
        inside = poly_deriv(self.f["rho_l"], self.xp.clip(x, -1.0, 1.0)) * self.inv_t_half
        return self.xp.where(self.xp.abs(x) > 1.0, 0.0, inside)

    def cp_l(self, t):
        return poly(self.f["cp_l"], self.xc(t))

    def h_fg(self, t):
        return poly(self.f["h_fg"], self.xc(t))

    def k_l(self, t):
        return poly(self.f["k_l"], self.xc(t))

    def mu_l(self, t):
        return self.xp.exp(poly(self.f["ln_mu_l"], self.xc(t)))

    def dh_l_dt(self, t):
        return poly(self.f["dh_l_sat"], self.xc(t))

    def h_l_above(self, x):
        return (poly_integral(self.f["dh_l_sat"], x) - self.base) * self.t_half

    def h_l(self, t):
        xp = self.xp
        below = (t - self.t_min) * self.cp_lo
        above = (t - self.t_max) * self.cp_hi + self.h_max
        inside = self.h_l_above(self.xc(t))
        h = xp.where(t >= self.t_max, above, inside)
        return xp.where(t <= self.t_min, below, h)

    def t_from_h_l(self, h):
        """`invert_h_l` from `FluidProps::t_from_h_l_k`'s start (the Rust RHS starts from a
        Hermite table, `fluids/inverse.rs`; both converge to the root within rounding)."""
        xp, b = self.xp, self.b
        dh = self.f["dh_l_sat"]
        below = h * (1.0 / self.cp_lo) + self.t_min
        above = (h - self.h_max) * (1.0 / self.cp_hi) + self.t_max
        le0, ge_max, nan = h <= 0.0, h >= self.h_max, xp.isnan(h)
        start = xp.clip(2.0 * h / self.h_max - 1.0, -1.0, 1.0)
        start = xp.where(nan, 0.0, start)
        one = xp.ones_like(h)

        def body(c):
            x, lo, hi, done = c
            f = self.h_l_above(x) - h
            zero = f == 0.0
            moving = ~done & ~zero
            hi = xp.where(moving & (f > 0.0), x, hi)
            lo = xp.where(moving & (f < 0.0), x, lo)
            x_newton = x - f / (poly(dh, x) * self.t_half)
            converged = xp.abs((x_newton - x) * self.t_half) <= self.t_of(x) * T_FROM_H_TOL
            inside = (x_newton > lo) & (x_newton < hi)
            nxt = xp.where(inside, x_newton, (lo + hi) * 0.5)
            bracketed = (hi - lo) * self.t_half <= self.t_of(nxt) * T_FROM_H_TOL
            step = xp.where(converged, xp.clip(x_newton, -1.0, 1.0), nxt)
            x = xp.where(moving, step, x)
            done = done | zero | (moving & (converged | bracketed))
            return x, lo, hi, done

        x, _, _, _ = b.loop(
            FLUID_MAX_ITER, body, (start, -one, one, le0 | ge_max | nan), lambda c: c[3]
        )
        t = xp.where(ge_max, above, self.t_of(x))
        t = xp.where(le0, below, t)
        return xp.where(nan, h, t)

    def vapor_transport(self, t):
        xp = self.xp
        f = self.f
        l = xp.log(xp.clip(t, 1.0, 10000.0) / f["vapor_t_ref_k"])
        return (
            xp.exp(l * f["k_vapor_exp"]) * f["k_vapor_ref_w_per_m_k"],
            xp.exp(l * f["mu_vapor_exp"]) * f["mu_vapor_ref_pa_s"],
        )

    def vapor_ideal(self, t):
        xp, f = self.xp, self.f
        lo, hi = f["ideal_t_lo_k"], f["ideal_t_hi_k"]
        s_lo, s_hi = math.sqrt(lo), math.sqrt(hi)
        inv_span = 1.0 / (s_hi - s_lo)
        tc = xp.clip(t, lo, hi)
        s = xp.sqrt(tc)
        x = (s - s_lo) * (2.0 * inv_span) - 1.0
        q = dq = 0.0 * t
        for k in range(len(f["vapor_ideal"]) - 1, -1, -1):
            dq = dq * x + q
            q = q * x + f["vapor_ideal"][k]
        cv = q + dq * s * inv_span
        return (tc * q + cv * (t - tc)) * self.rs, cv * self.rs

    def virial(self, t, rho):
        xp, f = self.xp, self.f
        tau = f["t_crit_k"] / xp.maximum(t, 1.0)
        y = tau - 1.0
        r = rho * (1.0 / f["rho_crit_kg_per_m3"])
        z = u = dz = 0.0 * t
        for k in range(4, 0, -1):
            c = f["vapor_virial"][(k - 1) * 6 : k * 6]
            bb = db = 0.0 * t
            for j in range(5, -1, -1):
                bb = bb * y + c[j]
                if j > 0:
                    db = db * y + j * c[j]
            z = (z + bb) * r
            u = (u + tau * db * (1.0 / k)) * r
            dz = (dz + bb * (k + 1)) * r
        return z + 1.0, u, dz

    def vapor_h_res_at_tp(self, t, p):
        xp = self.xp
        rt = xp.maximum(t, 1.0) * self.rs
        rho = xp.maximum(p, 0.0) / rt
        for _ in range(2):
            z, _, dz = self.virial(t, rho)
            slope = xp.maximum(dz + 1.0, 0.1)
            rho = xp.maximum(rho - (rho * z - p / rt) / slope, rho * 0.5)
        z, u, _ = self.virial(t, rho)
        return (u + z - 1.0) * rt

    def vapor_state(self, t_k, rho):
        xp, f = self.xp, self.f
        t = xp.maximum(t_k, 1.0)
        tau = f["t_crit_k"] / t
        tau_over_t = tau * tau * (1.0 / f["t_crit_k"])
        y = tau - 1.0
        r = rho * (1.0 / f["rho_crit_kg_per_m3"])
        z = kz = u = b1_sum = u2 = 0.0 * t
        for k in range(4, 0, -1):
            c = f["vapor_virial"][(k - 1) * 6 : k * 6]
            bb = b1 = b2 = 0.0 * t
            for j in range(5, -1, -1):
                bb = bb * y + c[j]
                if j > 0:
                    b1 = b1 * y + j * c[j]
                if j > 1:
                    b2 = b2 * y + (j * (j - 1)) * c[j]
            kf = float(k)
            z = (z + bb) * r
            kz = (kz + bb * kf) * r
            u = (u + b1 * (1.0 / kf)) * r
            b1_sum = b1_sum * r + b1
            u2 = (u2 + b2 * (1.0 / kf)) * r
        rs = self.rs
        rt = t * rs
        z_full = z + 1.0
        rtc = rs * f["t_crit_k"]
        dz_dt = -tau_over_t * b1_sum * r
        return dict(
            z=z_full,
            u_res=u * rtc,
            du_res_dt=-tau_over_t * u2 * rtc,
            du_res_drho=b1_sum * (rtc / f["rho_crit_kg_per_m3"]),
            p=rho * rt * z_full,
            dp_dt=rho * rs * (z_full + t * dz_dt),
            dp_drho=rt * (kz + z_full),
        )


class Tank:
    """`TankLanes` (src/geometry.rs) from (R, L, k) per element; `shape` shared:
    0 cylinder, 1 capsule, 2 sphere."""

    def __init__(self, b, shape, radius, length, k):
        xp = b.xp
        self.b, self.xp, self.shape = b, xp, shape
        self.radius, self.length, self.k = radius, length, k
        self.e = (1.0 - k) * (1.0 + k)
        self.c = k * k * radius
        self.disc_area = PI * radius * radius
        if shape == 0:
            self.a = 0.0 * radius
            self.height = length
            self.volume = self.disc_area * length
            self.dome_volume = 0.0 * radius
            self.dome_area = self.disc_area
            self.wall_area = 2.0 * self.disc_area + 2.0 * PI * radius * length
        else:
            self.a = k * radius
            self.height = length + 2.0 * self.a
            self.dome_volume = 2.0 / 3.0 * PI * radius * radius * self.a
            self.volume = 2.0 * self.dome_volume + self.disc_area * length
            self.dome_area = self.zone_area(self.a)
            self.wall_area = 2.0 * self.dome_area + 2.0 * PI * radius * length
        del xp

    def liquid_height(self, volume):
        xp = self.xp
        v = xp.where(volume > 0.0, xp.minimum(volume, self.volume), 0.0)
        full = v >= self.volume
        if self.shape == 0:
            return xp.where(full, self.height, xp.minimum(v / self.disc_area, self.height))
        bottom = v <= self.dome_volume
        cap_v = xp.where(bottom, v, self.volume - v)
        w = self.a * cap_fraction(self.b, cap_v * 2.0 / self.dome_volume)
        cyl = xp.minimum(
            xp.maximum(self.a + (v - self.dome_volume) / self.disc_area, self.a),
            self.a + self.length,
        )
        top = xp.maximum(self.height - w, 0.0)
        z = xp.where(v < self.volume - self.dome_volume, cyl, top)
        z = xp.where(bottom, w, z)
        return xp.where(full, self.height, z)

    def clamp_z(self, z):
        return self.xp.where(z > 0.0, self.xp.minimum(z, self.height), 0.0)

    def dome_depth(self, z):
        xp = self.xp
        top = xp.maximum(self.height - z, 0.0)
        w = xp.where(z < self.a + self.length, self.a, top)
        return xp.where(z <= self.a, z, w)

    def surface_radius(self, z):
        if self.shape == 0:
            return self.radius + 0.0 * z
        xp = self.xp
        w = self.dome_depth(self.clamp_z(z))
        dome = xp.sqrt(w * (self.a * 2.0 - w)) / self.k
        return xp.where(w >= self.a, self.radius, dome)

    def interface_area(self, z):
        if self.shape == 0:
            return self.disc_area + 0.0 * z
        xp = self.xp
        w = self.dome_depth(self.clamp_z(z))
        dome = w * PI * (self.a * 2.0 - w) / (self.k * self.k)
        return xp.where(w >= self.a, self.disc_area, dome)

    def wetted_area(self, z_m):
        xp = self.xp
        z = self.clamp_z(z_m)
        if self.shape == 0:
            side = self.disc_area + self.radius * (2.0 * PI) * z
            return xp.where(z >= self.height, self.wall_area, side)
        z1 = self.a
        z2 = self.a + self.length
        bottom = z <= z1
        zone = self.zone_area(xp.where(bottom, z, self.height - z))
        cyl = self.dome_area + self.radius * (2.0 * PI) * (z - z1)
        top = xp.maximum(self.wall_area - zone, 0.0)
        return xp.where(bottom, zone, xp.where(z < z2, cyl, top))

    def wetted_area_slope(self, z):
        side = self.radius * (2.0 * PI)
        if self.shape == 0:
            return side + 0.0 * z
        w = self.dome_depth(self.clamp_z(z))
        dome = self.zone_integrand(w) * (2.0 * PI) / (self.k * self.k)
        return self.xp.where(w >= self.a, side, dome)

    def zone_integrand(self, w):
        xp = self.xp
        s = self.a - w
        oblate = xp.sqrt(self.c * self.c + self.e * s * s)
        prolate = xp.sqrt(self.a * self.a - self.e * w * (self.a * 2.0 - w))
        return xp.where(self.e >= 0.0, oblate, prolate)

    def zone_area(self, w):
        xp = self.xp
        a = self.a
        w = xp.minimum(xp.maximum(w, 0.0), a)
        s1 = a - w
        s2 = a
        big1 = self.zone_integrand(w)
        big2 = a
        c2 = self.c * self.c
        ds2 = w * (a * 2.0 - w)
        term1 = (c2 + self.e * (s1 * s1 + s2 * s2)) / (s2 * big2 + s1 * big1)
        cross = s2 * big1 + s1 * big2
        d = xp.sqrt(xp.abs(self.e)) * ds2 / cross
        series = d < SERIES_LIMIT
        oblate = self.e > 0.0
        g = xp.where(oblate, asinh_over_x(xp, d), asin_over_x(d))
        steep = ~oblate & ~series
        cos_d = (big1 * big2 + xp.abs(self.e) * s1 * s2) / c2
        g = xp.where(steep, xp.arctan2(d, cos_d) / d, g)
        term2 = c2 * g / cross
        integral = ds2 * 0.5 * (term1 + term2)
        area = integral * (2.0 * PI) / (self.k * self.k)
        return xp.where(w <= 0.0, 0.0, area)


def asinh_over_x(xp, x):
    x2 = x * x
    series = 1.0 - x2 * (1.0 / 6.0 - x2 * (3.0 / 40.0 - x2 * (5.0 / 112.0)))
    y = x + x2 / (xp.sqrt(x2 + 1.0) + 1.0)
    u = y + 1.0
    log1p = xp.log(u) - ((u - 1.0) - y) / u
    return xp.where(x < SERIES_LIMIT, series, log1p / x)


def asin_over_x(x):
    x2 = x * x
    return x2 * (x2 * (x2 * (5.0 / 112.0) + 3.0 / 40.0) + 1.0 / 6.0) + 1.0


def cap_fraction(b, q):
    xp = b.xp
    empty = xp.isnan(q) | (q <= 0.0)
    full = q >= 2.0
    lo = xp.sqrt(q / 3.0)
    hi = xp.minimum(xp.sqrt(q / 2.0), 1.0)
    # geometry.rs cap_fraction's start: two fixed-point rounds from each end, split at 0.8.
    low_start = lo
    for _ in range(2):
        low_start = xp.sqrt(q / (3.0 - low_start))
    r = 2.0 - q
    y = r * (1.0 / 3.0)
    for _ in range(2):
        y = (r + y * y * y) * (1.0 / 3.0)
    guess = xp.where(q < CAP_START_SPLIT, low_start, 1.0 - y)
    t = xp.where((guess > lo) & (guess < hi), guess, (lo + hi) * 0.5)

    def body(c):
        t, lo, hi, done = c
        f = t * t * (3.0 - t) - q
        moving = ~done & ~(f == 0.0)
        hi = xp.where(moving & (f > 0.0), t, hi)
        lo = xp.where(moving & (f < 0.0), t, lo)
        fp = t * 3.0 * (2.0 - t)
        newton = t - f / fp
        converged = xp.abs(newton - t) <= t * (2.0 * F64_EPS)
        nxt = xp.where((newton > lo) & (newton < hi), newton, (lo + hi) * 0.5)
        bracketed = (hi - lo) <= hi * F64_EPS
        t = xp.where(moving, xp.where(converged, newton, nxt), t)
        done = done | ~moving | converged | bracketed
        return t, lo, hi, done

    t, _, _, _ = b.loop(CAP_MAX_ROUNDS, body, (t, lo, hi, empty | full), lambda c: c[3])
    t = xp.where(full, 1.0, t)
    return xp.where(empty, 0.0, t)
