"""An IPC-style implicit step on a small cloth scene, with dhcd doing the collision work.

A 10 x 10 mass-spring sheet falls under gravity onto a fixed, slightly tilted sheet. Each
time step minimises the incremental potential

    E(x) = 1/2 |x - x_pred|_M^2 + h^2 (springs(x) + kappa * sum_k b(d_k^2(x)))

by Newton's method: the barrier b over the contact set (`dhcd.self_contact_set`: every
pair of features within dhat, once, with its squared distance and that distance's
gradient), its gradient and Gauss-Newton Hessian assembled from the set's derivatives, and
a backtracking line search that starts at the collision-free step size
(`dhcd.collision_free_stepsize`) and only shrinks it. It prints the time spent in dhcd per
time step, and checks that the cloth reached the floor and no pair ever touched.

Run: python python/examples/ipc_step.py [--steps 25] [--n 10]
"""

import argparse
import time

import numpy as np

import dhcd

ap = argparse.ArgumentParser()
ap.add_argument("--steps", type=int, default=25)
ap.add_argument("--n", type=int, default=10)
args = ap.parse_args()


def sheet(n, size, origin, tilt=0.0):
    """An n x n grid of 2 n^2 triangles in the plane z = origin_z + tilt * x."""
    xs, ys = np.meshgrid(np.linspace(0, size, n + 1), np.linspace(0, size, n + 1), indexing="ij")
    v = np.stack([xs.ravel(), ys.ravel(), tilt * xs.ravel()], axis=1) + np.asarray(origin)
    idx = lambda i, j: i * (n + 1) + j  # noqa: E731
    f = []
    for i in range(n):
        for j in range(n):
            f.append((idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)))
            f.append((idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)))
    return v, np.array(f, dtype=np.int64)


# The scene: the cloth (free) above the obstacle (fixed), one mesh.
cloth_v, cloth_f = sheet(args.n, 1.0, (0.0, 0.0, 0.08))
floor_v, floor_f = sheet(6, 1.6, (-0.3, -0.3, 0.0), tilt=0.05)
nc = len(cloth_v)
rest = np.vstack([cloth_v, floor_v])
faces = np.vstack([cloth_f, floor_f + nc])
free = np.zeros(len(rest), dtype=bool)
free[:nc] = True
dofs = np.flatnonzero(np.repeat(free, 3))

h = 1.0 / 60.0
mass = 1.0 / nc  # per vertex: a 1 kg sheet
gravity = np.array([0.0, 0.0, -9.81])
k_spring = 200.0
dhat = 0.01
kappa = 1e4
edges_of_cloth = np.unique(np.sort(np.vstack([cloth_f[:, [0, 1]], cloth_f[:, [1, 2]], cloth_f[:, [2, 0]]]), axis=1), axis=0)
rest_len = np.linalg.norm(cloth_v[edges_of_cloth[:, 0]] - cloth_v[edges_of_cloth[:, 1]], axis=1)

hier = dhcd.Hierarchy(rest, faces)


def assemble(n, idx, grad, hess_blocks):
    """Scatter per-element gradients `(m, k)` and Hessian blocks `(m, k, k)` at dof indices
    `idx` `(m, k)` (negative: unused) into a dense gradient and Hessian of size n."""
    used = idx >= 0
    g = np.zeros(n)
    np.add.at(g, idx[used], grad[used])
    H = None
    if hess_blocks is not None:
        H = np.zeros((n, n))
        both = used[:, :, None] & used[:, None, :]
        rows = np.broadcast_to(idx[:, :, None], hess_blocks.shape)
        cols = np.broadcast_to(idx[:, None, :], hess_blocks.shape)
        np.add.at(H, (rows[both], cols[both]), hess_blocks[both])
    return g, H


def springs(x, need_hessian=True):
    """Energy, gradient and (projected) Hessian of the cloth's edge springs."""
    d = x[edges_of_cloth[:, 1]] - x[edges_of_cloth[:, 0]]
    length = np.linalg.norm(d, axis=1)
    stretch = length - rest_len
    e = 0.5 * k_spring * np.sum(stretch**2)
    u = d / length[:, None]
    f = (k_spring * stretch)[:, None] * u
    idx = (3 * edges_of_cloth[:, :, None] + np.arange(3)).reshape(-1, 6)
    blocks = None
    if need_hessian:
        # k (u u^T + max(s / L, 0) (I - u u^T)) per spring, in the pattern [[B, -B], [-B, B]].
        uu = u[:, :, None] * u[:, None, :]
        c = np.maximum(stretch / length, 0.0)[:, None, None]
        b = k_spring * (uu + c * (np.eye(3) - uu))
        blocks = np.block([[b, -b], [-b, b]])
    g, H = assemble(x.size, idx, np.hstack([-f, f]), blocks)
    return e, g, H


def barrier(s):
    """IPC's barrier on squared distances, b(s) = -(s - s_hat)^2 log(s / s_hat), with b' and
    b''."""
    sh = dhat * dhat
    inside = s < sh
    s = np.where(inside, s, sh)
    lg = np.log(s / sh)
    b = np.where(inside, -((s - sh) ** 2) * lg, 0.0)
    db = np.where(inside, -2 * (s - sh) * lg - (s - sh) ** 2 / s, 0.0)
    ddb = np.where(inside, -2 * lg - 4 * (s - sh) / s + (s - sh) ** 2 / s**2, 0.0)
    return b, db, ddb


timing = {"dhcd": 0.0}


def contact_terms(x, need_hessian):
    """Barrier energy, gradient and Gauss-Newton Hessian over the contact set at x."""
    s0 = time.perf_counter()
    hier.update(x)
    cs = dhcd.self_contact_set(hier, dhat)
    grad_s = cs.gradient() if need_hessian else None
    timing["dhcd"] += time.perf_counter() - s0
    b, db, ddb = barrier(cs.distance_sq)
    if not need_hessian:
        return np.sum(b), None, None, cs
    # Dof indices of each row's four vertex slots (-1 where a slot is unused).
    v = cs.vertices
    idx = np.where(np.repeat(v >= 0, 3, axis=1), (3 * v[:, :, None] + np.arange(3)).reshape(-1, 12), -1)
    # Gauss-Newton: b'' grad(d^2) grad(d^2)^T, positive where b'' is.
    blocks = ddb[:, None, None] * grad_s[:, :, None] * grad_s[:, None, :]
    g, H = assemble(x.size, idx, db[:, None] * grad_s, blocks)
    return np.sum(b), g, H, cs


def energy(x, x_pred):
    inertia = 0.5 * mass * np.sum((x[free] - x_pred[free]) ** 2)
    es, _, _ = springs(x, need_hessian=False)
    eb, _, _, _ = contact_terms(x, False)
    return inertia + h * h * (es + kappa * eb)


x = rest.copy()
v = np.zeros_like(x)
print(f"cloth {len(cloth_f)} + floor {len(floor_f)} triangles, dhat {dhat}, h {h:.4f}")
least_gap = np.inf
for step in range(args.steps):
    timing["dhcd"] = 0.0
    started = time.perf_counter()
    x_pred = x + h * v
    x_pred[free] += h * h * gravity
    y = x.copy()
    contacts = 0
    for newton in range(20):
        es, gs, Hs = springs(y)
        eb, gb, Hb, cs = contact_terms(y, True)
        contacts = len(cs)
        g = mass * (y - x_pred).ravel() * np.repeat(free, 3) + h * h * (gs + kappa * gb)
        H = mass * np.eye(y.size) + h * h * (Hs + kappa * Hb)
        p = np.zeros(y.size)
        p[dofs] = np.linalg.solve(H[np.ix_(dofs, dofs)], -g[dofs])
        # IPC's stopping rule: the Newton step, per unit time, below 1e-3 of the scene size.
        if np.max(np.abs(p)) < 1e-3 * h:
            break
        target = y + p.reshape(-1, 3)
        s0 = time.perf_counter()
        alpha = dhcd.collision_free_stepsize(hier, y, target)
        timing["dhcd"] += time.perf_counter() - s0
        e0 = energy(y, x_pred)
        while alpha > 1e-12 and energy(y + alpha * p.reshape(-1, 3), x_pred) > e0:
            alpha *= 0.5
        y = y + alpha * p.reshape(-1, 3)
    v = (y - x) / h
    x = y
    if contacts:
        least_gap = min(least_gap, float(np.sqrt(cs.distance_sq.min())))
    total = time.perf_counter() - started
    print(
        f"step {step:2d}: {newton + 1:2d} Newton iterations, {contacts:4d} contacts, "
        f"lowest cloth z {x[:nc, 2].min():+.4f}, collision time {timing['dhcd'] * 1e3:6.1f} ms "
        f"of {total * 1e3:6.1f} ms"
    )

# The cloth came to rest on the floor without passing through it.
assert least_gap > 0.0, "a pair touched"
assert np.isfinite(least_gap), "the cloth never reached the floor"
print(f"closest pair over the run: {least_gap:.3g} (dhat {dhat})")
