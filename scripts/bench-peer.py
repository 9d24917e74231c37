#!/usr/bin/python3
"""The scipy peer of `brdf-factor bench fit`: the same homomorphic least-squares
fit (docs/design.md §3.2) written in plain numpy/scipy, timed interleaved with
the C++ fit in one run (docs/speed.md, "The scipy peer").

Input: the C++ side writes the joint solve's input once (`bench fit
--dump-input FILE`: the valid samples' points in the terms' parameterization,
weights, log targets with the fixed terms taken off, the joint terms'
projections and projection masks, the fit's unknowns and rel_mse). The peer
reads it (untimed, like the C++ side's FitData) and then, per fit, does what a
fit does: projection to texel coordinates, projection mask (convex hull of the
16 projected cube corners), bilinear lookups, the unknowns (mask plus every
texel a sample reads), B as a scipy.sparse matrix, the normal equations
B^T W B + mu L^T L + gauge + ridge, a dense Cholesky (scipy.linalg.cho_factor/
cho_solve, 3 right-hand sides) and the least-squares objective
sum_k w_k |b_k . y - r_k|^2 / (3 W), which is the C++ fit's rel_mse with
exact_error = false. The peer then checks that its unknowns and masks equal
the C++ fit's and its rel_mse equals the C++ one to --tol relative (default
1e-9), and exits 1 with both values otherwise: a peer that solves a different
problem proves nothing.

    /usr/bin/python3 scripts/bench-peer.py [--cli build/experiments/brdf-factor]
        [--brdf bluepaint --grid 16 --texture 16 --terms 2] [--rounds 9 --repeats 15]
    /usr/bin/python3 scripts/bench-peer.py --check --grid 8 --texture 8   (one fit, compare, no timing)

Prints one JSON line: both medians (wall and CPU ms per fit, median over rounds
of each round's median), their ratio peer / C++, the two rel_mse and the load
average before and after. Each round runs the CLI once (`bench fit --repeats
R`, its own median; process start-up and sampling are outside its timer) and
then R peer fits, so both see the same machine load. Single-threaded like
`bench fit`: the BLAS thread variables are set to 1 before numpy is imported.
Supported: non-reciprocal terms, extrapolation_prior 0 (what `bench fit` runs);
anything else is refused with a message.
"""
import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import scipy
import scipy.linalg
import scipy.ndimage
import scipy.sparse
import scipy.spatial

ROOT = pathlib.Path(__file__).resolve().parent.parent


class PeerError(Exception):
    """The peer's input or result does not match the C++ fit."""


def load_input(path):
    """The `bench fit --dump-input` file as numpy arrays (untimed, once)."""
    with open(path) as f:
        j = json.load(f)
    if j.get("format") != "brdf-factor bench-fit input 1":
        raise PeerError("%s: format: expected 'brdf-factor bench-fit input 1', found %r" % (path, j.get("format")))
    if j["extrapolation_prior"] != 0:
        raise PeerError("%s: extrapolation_prior: the peer supports 0 only, found %r" % (path, j["extrapolation_prior"]))
    n = j["samples"]
    d = {
        "x": np.asarray(j["x"], dtype=float).reshape(n, 4),
        "w": np.asarray(j["w"], dtype=float),
        "r": np.asarray(j["r"], dtype=float).T.copy(),  # N x 3
        "W": float(j["W"]),
        "smoothing": float(j["smoothing"]),
        "terms": [],
        "unknowns": int(j["unknowns"]),
        "rel_mse": float(j["rel_mse"]),
        "exact_error": bool(j["exact_error"]),
    }
    if d["exact_error"]:
        raise PeerError("%s: exact_error: the peer computes the least-squares objective (exact_error false)" % path)
    for i, t in enumerate(j["terms"]):
        if t["reciprocal"]:
            raise PeerError("%s: terms[%d].reciprocal: the peer supports non-reciprocal terms only" % (path, i))
        res = int(t["res"])
        d["terms"].append({"P": np.asarray(t["P"], dtype=float).reshape(2, 4), "res": res,
                           "mask": np.asarray(t["mask"], dtype=bool).reshape(res, res)})
    return d


def texel_coords(P, res, x):
    """docs/design.md §2.6: s = (P x / l1(P_r) + 1) / 2 (res - 1), for rows of x."""
    scale = 0.5 * (res - 1) / np.abs(P).sum(axis=1)
    return x @ (P * scale[:, None]).T + 0.5 * (res - 1)


def hull_distance(hull, p):
    """Distance of points p (K x 2) to a convex polygon (counter-clockwise
    vertices, H x 2); 0 inside."""
    a = hull[None, :, :]
    ab = np.roll(hull, -1, axis=0)[None, :, :] - a
    ap = p[:, None, :] - a
    cross = ab[..., 0] * ap[..., 1] - ab[..., 1] * ap[..., 0]
    t = np.clip((ap * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0.0, 1.0)
    dist = np.linalg.norm(a + t[..., None] * ab - p[:, None, :], axis=-1).min(axis=1)
    return np.where((cross >= 0).all(axis=1), 0.0, dist)


def projection_mask(P, res):
    """docs/design.md §2.6: texels whose centre is within 1e-9 of the hull of
    the 16 projected corners of [-1, 1]^4, their 8 neighbours, and the corners
    of every cell whose centre is within 0.7072 texel of the hull. res x res,
    [j, i]."""
    corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * 4, indexing="ij")).reshape(4, -1).T
    pts = texel_coords(P, res, corners)
    hull = pts[scipy.spatial.ConvexHull(pts).vertices]  # counter-clockwise in 2-D
    j, i = np.mgrid[0:res, 0:res]
    centres = np.column_stack([i.ravel(), j.ravel()]).astype(float)
    inside = (hull_distance(hull, centres) <= 1e-9).reshape(res, res)
    mask = scipy.ndimage.binary_dilation(inside, structure=np.ones((3, 3), bool))
    cell = (hull_distance(hull, centres + 0.5) <= 0.7072).reshape(res, res)[:-1, :-1]
    mask[:-1, :-1] |= cell
    mask[1:, :-1] |= cell
    mask[:-1, 1:] |= cell
    mask[1:, 1:] |= cell
    return mask


def grid_laplacian(mask, first, M):
    """Graph Laplacian of the mask's 4-neighbour grid, on unknowns numbered
    from `first` in texel order, as an M x M sparse matrix."""
    unk = np.full(mask.shape, -1)
    unk[mask] = first + np.arange(mask.sum())
    h = mask[:, :-1] & mask[:, 1:]
    v = mask[:-1, :] & mask[1:, :]
    p = np.concatenate([unk[:, :-1][h], unk[:-1, :][v]])
    q = np.concatenate([unk[:, 1:][h], unk[1:, :][v]])
    adj = scipy.sparse.coo_matrix((np.ones(len(p)), (p, q)), shape=(M, M)).tocsr()
    adj = adj + adj.T
    return scipy.sparse.diags(np.asarray(adj.sum(axis=1)).ravel()) - adj


def fit(d):
    """One joint fit of d's terms. Returns (rel_mse, unknowns, masks, Y)."""
    x, w, r = d["x"], d["w"], d["r"]
    n = len(w)
    sw = np.sqrt(w)
    cols, vals, masks = [], [], []
    M = 0
    firsts = []
    for t in d["terms"]:
        res = t["res"]
        s = np.clip(texel_coords(t["P"], res, x), 0.0, res - 1)
        ij = np.minimum(s.astype(int), res - 2)  # s >= 0: truncation is floor
        a, b = (s - ij).T
        cell = ij[:, 1] * res + ij[:, 0]
        corner = cell[:, None] + np.array([0, 1, res, res + 1])
        mask = projection_mask(t["P"], res).ravel()
        masks.append(mask.copy())
        mask[corner.ravel()] = True  # every texel a sample reads is an unknown
        unk = np.full(res * res, -1)
        unk[mask] = M + np.arange(mask.sum())
        firsts.append((M, int(mask.sum()), mask.reshape(res, res)))
        M += int(mask.sum())
        cols.append(unk[corner])
        vals.append(np.column_stack([(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b]))
    k = 4 * len(d["terms"])
    # sqrt(W) B, one row per sample, k entries per row.
    Bs = scipy.sparse.csr_matrix(((np.hstack(vals) * sw[:, None]).ravel(), np.hstack(cols).ravel(),
                                  np.arange(0, k * n + 1, k)), shape=(n, M))
    rs = r * sw[:, None]
    mu = d["smoothing"] * d["W"] / M
    L = sum(grid_laplacian(m, first, M) for first, _, m in firsts)
    A = (Bs.T @ Bs + mu * (L.T @ L)).toarray()
    rhs = Bs.T @ rs
    mean_diag = np.trace(A) / M
    for first, count, _ in firsts[1:]:  # gauge: gamma (sum of the term's texels)^2
        A[first:first + count, first:first + count] += mean_diag / count
    A[np.diag_indices(M)] += 1e-12 * mean_diag + np.finfo(float).tiny  # ridge
    Y = scipy.linalg.cho_solve(scipy.linalg.cho_factor(A, lower=True, overwrite_a=True, check_finite=False),
                               rhs, overwrite_b=True, check_finite=False)
    rel_mse = float(((Bs @ Y - rs) ** 2).sum() / (3.0 * d["W"]))
    return rel_mse, M, masks, Y


def check(d, rel_mse, M, masks, cpp_rel_mse, tol, what):
    """Raises PeerError unless the peer solved the C++ fit's problem."""
    for i, (m, t) in enumerate(zip(masks, d["terms"])):
        if not np.array_equal(m, t["mask"].ravel()):
            diff = np.flatnonzero(m != t["mask"].ravel())
            raise PeerError("%s: term %d's projection mask differs from the C++ one at texels %s"
                            % (what, i + 1, diff[:10].tolist()))
    if M != d["unknowns"]:
        raise PeerError("%s: unknowns: C++ %d, peer %d" % (what, d["unknowns"], M))
    rel = abs(rel_mse - cpp_rel_mse) / abs(cpp_rel_mse)
    if not rel <= tol:
        raise PeerError("%s: rel_mse: C++ %.17g, peer %.17g, relative difference %.3g > %g"
                        % (what, cpp_rel_mse, rel_mse, rel, tol))
    return rel


def run_cli(cli, args, repeats, dump=None):
    cmd = [cli, "bench", "fit", "--brdf", args.brdf, "--grid", str(args.grid), "--texture", str(args.texture),
           "--terms", str(args.terms), "--parameterization", args.parameterization, "--seed", str(args.seed), "--repeats", str(repeats)]
    if dump:
        cmd += ["--dump-input", dump]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise PeerError("%s failed (exit %d): %s" % (" ".join(cmd), p.returncode, p.stderr.strip()))
    return json.loads(p.stdout.strip().splitlines()[-1])


def time_peer(d, repeats):
    wall, cpu, last = [], [], None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        last = fit(d)
        cpu.append(1e3 * (time.process_time() - c0))
        wall.append(1e3 * (time.perf_counter() - t0))
    return statistics.median(wall), statistics.median(cpu), last


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cli", default=str(ROOT / "build" / "experiments" / "brdf-factor"), help="brdf-factor CLI")
    ap.add_argument("--brdf", default="bluepaint")
    ap.add_argument("--grid", type=int, default=16)
    ap.add_argument("--texture", type=int, default=16)
    ap.add_argument("--terms", type=int, default=2,
                    help="bench fit's --terms (the last 2 are solved jointly; earlier ones are in the targets)")
    ap.add_argument("--parameterization", default="wiwo", help="wiwo or halfdiff")
    ap.add_argument("--seed", type=int, default=1, help="bench fit's seed of the random projections")
    ap.add_argument("--rounds", type=int, default=9, help="interleaved rounds (C++ call, then peer fits)")
    ap.add_argument("--repeats", type=int, default=15, help="fits per round on each side")
    ap.add_argument("--tol", type=float, default=1e-9, help="largest relative rel_mse difference accepted")
    ap.add_argument("--check", action="store_true", help="one fit and the comparison, no timing")
    ap.add_argument("--perturb-smoothing", type=float, default=1.0, help=argparse.SUPPRESS)  # tests: a different problem
    args = ap.parse_args(argv)
    if args.rounds < 1 or args.repeats < 1:
        ap.error("--rounds and --repeats: expected >= 1, found %d and %d" % (args.rounds, args.repeats))
    if not os.access(args.cli, os.X_OK):
        ap.error("--cli: %s is not an executable (build brdf-factor first)" % args.cli)
    load0 = os.getloadavg()
    try:
        with tempfile.TemporaryDirectory() as tmp:
            dump = os.path.join(tmp, "input.json")
            first = run_cli(args.cli, args, 1, dump)
            d = load_input(dump)
        d["smoothing"] *= args.perturb_smoothing
        out = {"bench": "fit-peer", "brdf": args.brdf, "grid": args.grid, "texture": args.texture,
               "terms": args.terms, "parameterization": args.parameterization, "samples": len(d["w"]), "unknowns": d["unknowns"]}
        if args.check:
            rel_mse, M, masks, _ = fit(d)
            out["rel_diff"] = check(d, rel_mse, M, masks, d["rel_mse"], args.tol, "check")
            out.update(rel_mse_cpp=d["rel_mse"], rel_mse_peer=rel_mse)
            print(json.dumps(out), flush=True)
            return 0
        cpp_ms, cpp_cpu, peer_ms, peer_cpu, rels = [], [], [], [], []
        for rnd in range(args.rounds):
            c = run_cli(args.cli, args, args.repeats)
            pw, pc, (rel_mse, M, masks, _) = time_peer(d, args.repeats)
            rels.append(check(d, rel_mse, M, masks, c["rel_mse"], args.tol, "round %d" % (rnd + 1)))
            cpp_ms.append(c["ms_median"])
            cpp_cpu.append(c["cpu_ms_median"])
            peer_ms.append(pw)
            peer_cpu.append(pc)
        med = statistics.median
        out.update(rounds=args.rounds, repeats=args.repeats,
                   peer_ms_median=med(peer_ms), cpp_ms_median=med(cpp_ms), ratio=med(peer_ms) / med(cpp_ms),
                   peer_cpu_ms_median=med(peer_cpu), cpp_cpu_ms_median=med(cpp_cpu),
                   cpu_ratio=med(peer_cpu) / med(cpp_cpu),
                   peer_ms_rounds=[round(v, 3) for v in peer_ms], cpp_ms_rounds=[round(v, 3) for v in cpp_ms],
                   rel_mse_cpp=first["rel_mse"], rel_mse_peer=rel_mse, rel_diff_max=max(rels),
                   kernel=first.get("kernel"), numpy=np.__version__, scipy=scipy.__version__,
                   loadavg_start=[round(v, 2) for v in load0], loadavg_end=[round(v, 2) for v in os.getloadavg()])
        print(json.dumps(out), flush=True)
        return 0
    except PeerError as e:
        print("bench-peer: FAILED: %s" % e, file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
