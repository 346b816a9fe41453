"""Linear potential-flow sloshing modes of an axisymmetric tank (first azimuthal harmonic).

Run by hand (numpy + scipy); `tools/slosh_tables.py` uses it to write the committed tables.

Problem (lengths over the tank radius R): phi = Phi(r, z) cos(theta), Laplace in the liquid,
dphi/dn = 0 on the wetted wall, dphi/dz = lambda phi on the flat free surface z = z_s, with
lambda = omega^2 / g (times R: the returned `lam` is omega^2 R / g). Weak form on the meridian
half-plane:

    int (Phi_r^2 + Phi_z^2 + Phi^2 / r^2) r dr dz = lambda int_surface Phi^2 r dr,

with Phi = 0 on the axis. Discretisation: isoparametric quadratic (P2) triangles on a Delaunay
mesh (nodes and edge midpoints on the curved wall lie exactly on it), degree-5 quadrature,
static condensation onto the free-surface nodes, dense generalised eigenproblem.

Mechanical analog (Dodge 2000 ch. 3 / Abramson SP-106 ch. 6), from the modal participation of a
lateral container acceleration X'': with N_n = int_S phi_n^2 dS, P_n = int_S x phi_n dS and
I_n = int_V x dphi_n/dz dV (x = r cos theta),
    slosh mass      m_n = rho lambda_n P_n^2 / N_n            (force balance),
    pendulum length L_n = 1 / lambda_n                        (omega_n^2 = g / L_n),
    hinge height    z_h = (P_n - 2 I_n) / (lambda_n P_n)      (moment balance, above the surface).
The moment: the wall moment of the dynamic pressure p = -rho a_n'' phi_n is the closed-boundary
integral of p (r x n) = int_V r x grad(p) dV minus the free-surface part; Green's identity with
the harmonic xz (its flux vanishes on the wall, and xz = 0 on the surface z = 0) turns
int_V z dphi/dx dV into -I_n, so the wall moment is rho a_n'' (2 I_n - P_n) and the force
-rho a_n'' lambda_n P_n; their ratio is the height at which the mode's force acts (the hinge).
For the flat-bottom cylinder these reduce to the SP-106 closed forms: m_n / m_l =
2 tanh(xi h) / (xi (xi^2 - 1) h), z_h = L_n (2 sech(xi h) - 1), i.e. the mass
(2/xi) tanh(xi h / 2) below the surface (Dodge 2000 eq. 3.3); `python3 tools/slosh_fem.py` checks.
"""

import math
import sys

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import Delaunay

XI = (1.841183781, 5.331442774)

# Degree-5 seven-point rule on the reference triangle (Dunavant), weights summing to 1/2.
_A1, _B1, _W1 = 0.059715871789770, 0.470142064105115, 0.132394152788506
_A2, _B2, _W2 = 0.797426985353087, 0.101286507323456, 0.125939180544827
QP = np.array(
    [[1 / 3, 1 / 3], [_B1, _B1], [_A1, _B1], [_B1, _A1], [_B2, _B2], [_A2, _B2], [_B2, _A2]]
)
QW = 0.5 * np.array([0.225, _W1, _W1, _W1, _W2, _W2, _W2])
# Gauss-Legendre on [0, 1] for the surface edges.
_G, _GW = np.polynomial.legendre.leggauss(4)
GP, GW = 0.5 * (_G + 1.0), 0.5 * _GW


def shape_p2(xi, eta):
    """P2 shape functions and their (xi, eta) derivatives: vertices 0-2, midsides 01, 12, 20."""
    l1 = 1.0 - xi - eta
    n = np.array(
        [l1 * (2 * l1 - 1), xi * (2 * xi - 1), eta * (2 * eta - 1), 4 * l1 * xi, 4 * xi * eta, 4 * eta * l1]
    )
    dxi = np.array([-(4 * l1 - 1), 4 * xi - 1, 0.0, 4 * (l1 - xi), 4 * eta, -4 * eta])
    deta = np.array([-(4 * l1 - 1), 0.0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l1 - eta)])
    return n, np.stack([dxi, deta], axis=1)


QSHAPE = [shape_p2(x, e) for x, e in QP]


class Wall:
    """Meridian of a tank of radius 1: 'cylinder' (flat bottom) or a capsule of dome ratio k and
    barrel length L (k = 1, L = 0 is the sphere), parameterised by t from the bottom pole."""

    def __init__(self, kind, k=1.0, length=0.0):
        self.kind, self.k, self.length = kind, k, length
        if kind == "cylinder":
            self.breaks = [0.0, 1.0, 1.0 + length]
        else:
            self.breaks = [0.0, math.pi / 2, math.pi / 2 + length, math.pi + length]

    def height(self):
        return self.length if self.kind == "cylinder" else self.length + 2 * self.k

    def point(self, t):
        t = np.asarray(t, dtype=float)
        if self.kind == "cylinder":
            return np.where(t <= 1.0, t, 1.0), np.where(t <= 1.0, 0.0, t - 1.0)
        k, L = self.k, self.length
        th_b = np.minimum(t, math.pi / 2)
        th_t = np.clip(t - (math.pi / 2 + L), 0.0, math.pi / 2)
        r = np.where(t <= math.pi / 2, np.sin(th_b), np.where(t <= math.pi / 2 + L, 1.0, np.cos(th_t)))
        z = np.where(
            t <= math.pi / 2,
            k * (1 - np.cos(th_b)),
            np.where(t <= math.pi / 2 + L, k + (t - math.pi / 2), k + L + k * np.sin(th_t)),
        )
        return r, z

    def t_of_z(self, zs):
        lo, hi = 0.0, self.breaks[-1]
        if self.kind == "cylinder":
            lo = 1.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if self.point(mid)[1] < zs:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    def volume(self, zs):
        """Liquid volume below z_s over R^3."""
        if self.kind == "cylinder":
            return math.pi * zs
        k, L = self.k, self.length
        cap = lambda w: math.pi * w * w * (3 * k - w) / (3 * k * k)
        vd = 2 / 3 * math.pi * k
        if zs <= k:
            return cap(zs)
        if zs <= k + L:
            return vd + math.pi * (zs - k)
        return 2 * vd + math.pi * L - cap(self.height() - zs)


def mesh(wall, zs, n):
    """P2 mesh of the liquid below z_s: (nodes (M, 2) as (r, z), triangles (E, 6), wall t)."""
    ts = wall.t_of_z(zs)
    rs = float(wall.point(ts)[0])
    zb = 0.0
    depth = zs - zb
    sx = rs
    sz = min(depth, rs)
    h0 = 1.0 / n

    def spacing(zz):  # spacing in scaled units at height zz (graded with depth below rs)
        d = (zs - zz) / sz
        return h0 * (1.0 + 0.35 * max(0.0, d - 1.0))

    # Wall nodes from the contact point down to the pole, breakpoints kept.
    tw = np.linspace(0.0, ts, 20001)
    rw, zw = wall.point(tw)
    seg = np.hypot(np.diff(rw) / sx, np.diff(zw) / sz)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    wall_t = [ts]
    a = arc[-1]
    stops = sorted({b for b in wall.breaks if 0.0 < b < ts})
    stop_arcs = [np.interp(b, tw, arc) for b in stops]
    while True:
        zz = float(np.interp(a, arc, zw))
        step = spacing(zz)
        nxt = [sa for sa in stop_arcs if a - step * 1.3 < sa < a - 1e-12]
        if nxt:
            a = max(nxt)
            # keep near-stop spacing regular: avoid a sliver just above a breakpoint
        else:
            a = a - step
        if a <= 0.6 * spacing(0.0) * (1 if wall.kind != "cylinder" else 0) + 1e-12:
            break
        wall_t.append(float(np.interp(a, arc, tw)))
    wall_t.append(0.0)
    wall_t = np.array(wall_t)
    if wall.kind == "cylinder":
        wall_t = wall_t[wall_t > 1e-12]  # the bottom ends at the axis node added below
    wr, wz = wall.point(wall_t)
    pts = [np.stack([wr, wz], axis=1)]
    nwall = len(wall_t)
    # Free surface (r from the axis to the contact point, both ends excluded) and axis.
    m = max(2, int(round(1.0 / h0)))
    rsurf = np.linspace(0.0, rs, m + 1)[:-1]
    pts.append(np.stack([rsurf, np.full_like(rsurf, zs)], axis=1))
    zax = [zs]
    while True:
        nz = zax[-1] - spacing(zax[-1]) * sz
        if nz <= zb + 0.5 * spacing(zb) * sz:
            break
        zax.append(nz)
    zax = np.array(zax[1:])
    pts.append(np.stack([np.zeros_like(zax), zax], axis=1))
    if wall.kind == "cylinder":
        pts.append(np.array([[0.0, 0.0]]))
    bnd = np.concatenate(pts)
    # Interior rows.
    inner = []
    z = zs
    while True:
        z -= spacing(z) * sz
        if z <= zb:
            break
        tz = wall.t_of_z(z)
        rmax = float(wall.point(tz)[0])
        h = spacing(z) * sx
        for r in np.arange(h, rmax, h):
            inner.append((r, z))
    inner = np.array(inner).reshape(-1, 2)
    if len(inner):
        sc = np.array([1 / sx, 1 / sz])
        from scipy.spatial import cKDTree

        dist, _ = cKDTree(bnd * sc).query(inner * sc)
        loc = np.array([spacing(zz) for zz in inner[:, 1]])
        inner = inner[dist > 0.55 * loc]
    verts = np.concatenate([bnd, inner])
    tri = Delaunay(verts * np.array([1 / sx, 1 / sz])).simplices
    p = verts[tri]
    area = 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    keep = np.abs(area) > 1e-14 * sx * sz
    tri = tri[keep]
    flip = area[keep] < 0
    tri[flip] = tri[flip][:, [0, 2, 1]]
    # Midside nodes; wall edges (consecutive wall nodes) get the curve's midpoint.
    nodes = list(map(tuple, verts))
    edge_id = {}
    elems = np.zeros((len(tri), 6), dtype=int)
    elems[:, :3] = tri
    for e, (i, j, kk) in enumerate(tri):
        for slot, (u, v) in zip((3, 4, 5), ((i, j), (j, kk), (kk, i))):
            key = (min(u, v), max(u, v))
            if key not in edge_id:
                if key[0] < nwall and key[1] < nwall and key[1] - key[0] == 1:
                    tm = 0.5 * (wall_t[key[0]] + wall_t[key[1]])
                    mr, mz = wall.point(tm)
                    mid = (float(mr), float(mz))
                else:
                    mid = tuple(0.5 * (verts[u] + verts[v]))
                edge_id[key] = len(nodes)
                nodes.append(mid)
            elems[e, slot] = edge_id[key]
    return np.array(nodes), elems, rs


def solve(wall, zs, n=16, modes=2):
    """Modes of the liquid below z_s (over R): list of dicts with lam (= omega^2 R / g),
    mhat (= m_n / (rho R^3)), ratio (= m_n / m_l), length (= L_n / R), hinge (= z_h / R)."""
    x, el, rs = mesh(wall, zs, n)
    nn = len(x)
    X = x[el]  # (E, 6, 2)
    rows = np.repeat(el, 6, axis=1).ravel()
    cols = np.tile(el, (1, 6)).ravel()
    kvals = np.zeros((len(el), 6, 6))
    iz = np.zeros(nn)  # int Phi_z r^2 dr dz as a row vector
    vol = 0.0
    for (nq, dq), w in zip(QSHAPE, QW):
        J = np.einsum("eai,aj->eij", X, dq)  # dx_i / dxi_j
        det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
        inv = np.stack(
            [np.stack([J[:, 1, 1], -J[:, 0, 1]], -1), np.stack([-J[:, 1, 0], J[:, 0, 0]], -1)], 1
        ) / det[:, None, None]
        g = np.einsum("aj,eji->eai", dq, inv)  # dN_a / dx_i
        r = X[:, :, 0] @ nq
        wd = w * np.abs(det)
        kvals += (np.einsum("eai,ebi->eab", g, g) * r[:, None, None] + np.einsum("a,b->ab", nq, nq)[None] / r[:, None, None]) * wd[:, None, None]
        np.add.at(iz, el, g[:, :, 1] * (r * r * wd)[:, None])
        vol += float(np.sum(r * wd)) * 2 * math.pi
    K = sp.csr_matrix((kvals.ravel(), (rows, cols)), shape=(nn, nn))
    on_axis = x[:, 0] < 1e-12
    on_surf = np.abs(x[:, 1] - zs) < 1e-12 * max(1.0, zs)
    S = np.where(on_surf & ~on_axis)[0]
    Iin = np.where(~on_surf & ~on_axis)[0]
    # Surface mass and int Phi r^2 dr on the P2 surface edges.
    sidx = np.argsort(x[S, 0])
    S = S[sidx]
    pos = {g_: i for i, g_ in enumerate(S)}
    surf_nodes = np.where(on_surf)[0]
    order = surf_nodes[np.argsort(x[surf_nodes, 0])]
    # vertices are at even positions along the surface (P2 edge: vertex, mid, vertex)
    M = np.zeros((len(S), len(S)))
    pr2 = np.zeros(len(S))
    for a in range(0, len(order) - 2, 2):
        tri3 = order[a : a + 3]
        r0, r2 = x[tri3[0], 0], x[tri3[2], 0]
        for s, wq in zip(GP, GW):
            nloc = np.array([(1 - s) * (1 - 2 * s), 4 * s * (1 - s), s * (2 * s - 1)])
            rq = r0 + s * (r2 - r0)
            jac = r2 - r0
            for i_, gi in enumerate(tri3):
                if gi not in pos:
                    continue
                pr2[pos[gi]] += wq * jac * nloc[i_] * rq * rq
                for j_, gj in enumerate(tri3):
                    if gj in pos:
                        M[pos[gi], pos[gj]] += wq * jac * nloc[i_] * nloc[j_] * rq
    Kss = K[S][:, S].toarray()
    Ksi = K[S][:, Iin]
    Kii = K[Iin][:, Iin].tocsc()
    lu = spla.splu(Kii)
    Z = lu.solve(Ksi.T.toarray())
    Kred = Kss - Ksi @ Z
    Kred = 0.5 * (Kred + Kred.T)
    lam, vec = sla.eigh(Kred, M, subset_by_index=[0, modes - 1])
    out = []
    v_l = wall.volume(zs)
    for n_ in range(modes):
        phi = np.zeros(nn)
        phi[S] = vec[:, n_]
        phi[Iin] = -Z @ vec[:, n_]
        N = math.pi * vec[:, n_] @ M @ vec[:, n_]
        P = math.pi * pr2 @ vec[:, n_]
        Iv = math.pi * iz @ phi
        lamn = float(lam[n_])
        mhat = lamn * P * P / N
        out.append(
            dict(
                lam=lamn,
                mhat=mhat,
                ratio=mhat / v_l,
                length=1.0 / lamn,
                hinge=(P - 2 * Iv) / (lamn * P),
                rs=rs,
                vol_err=vol / v_l - 1.0,
            )
        )
    return out


def cylinder_closed_form(n, h):
    xi = XI[n]
    th = math.tanh(xi * h)
    return dict(
        lam=xi * th,
        ratio=2 * th / (xi * (xi * xi - 1) * h),
        hinge=(2 / math.cosh(xi * h) - 1) / (xi * th),
    )


def check(n=16):
    """The verifications quoted in docs/PHYSICS.md."""
    worst = 0.0
    for h in (0.1, 0.3, 1.0, 2.0, 3.0):
        res = solve(Wall("cylinder", length=h + 1.0), h, n)
        for m in range(2):
            ref = cylinder_closed_form(m, h)
            for key in ("lam", "ratio"):
                err = res[m][key] / ref[key] - 1
                worst = max(worst, abs(err))
                print(f"cylinder h/R={h} mode {m+1} {key}: {res[m][key]:.6f} vs {ref[key]:.6f} ({err:+.1e})")
            print(f"   hinge {res[m]['hinge']:.6f} vs {ref['hinge']:.6f}")
    print(f"cylinder worst relative error {worst:.2e}")
    sph = Wall("capsule", 1.0, 0.0)
    half = solve(sph, 1.0, n)
    print(f"half-full sphere: omega^2 R/g = {half[0]['lam']:.5f} (McIver 1989: 1.5602), "
          f"{half[0]['lam'] / 1.5602 - 1:+.2e}; m1/m_l = {half[0]['ratio']:.4f}")
    for zs in (0.2, 0.1, 0.05, 0.02):
        print(f"sphere depth {zs}: omega^2 R/g = {solve(sph, zs, n)[0]['lam']:.5f}")


if __name__ == "__main__":
    check(int(sys.argv[1]) if len(sys.argv) > 1 else 16)
