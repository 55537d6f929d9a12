"""Latency-aware iterated local search for the WTRP (GILS-RVND, Silva et al. 2012, "A simple
and effective metaheuristic for the Minimum Latency Problem"), generalised to node weights.

Structure (as in GILS-RVND): multi-start; each start builds a randomized greedy solution
(restricted candidate list of size alpha * |CL|, alpha drawn from {0, 0.01, ..., 0.25}), then
iterated local search: RVND (random variable neighbourhood descent over swap, 2-opt, or-opt
of 1, 2 and 3 nodes, best improvement in each) and a double-bridge perturbation of the best
solution of this start; a start ends after ``I_ILS = min(n, ils_iters)`` perturbations
without improvement.

Every move is evaluated in O(1) by concatenating subsequence data. For a subsequence sigma
(forward, or reversed for 2-opt) we use
  T(sigma): duration (sum of arc costs inside sigma),
  C(sigma): weighted latency of its nodes measured from its first node (sum W_v * arrival_v),
  W(sigma): weight sum,
and concatenation is T = T1 + d + T2, C(s1 + s2) = C1 + W2 * (T1 + d) + C2, W = W1 + W2 with
d = M[last(s1), first(s2)]. GILS-RVND tabulates all O(n^2) subsequences; here (T, C, W) of any
segment, forward or reversed, comes in O(1) from five O(n) prefix sums of the current solution
(forward arrival times F, reverse-arc arrival times R, and the prefix sums of w, w F, w R),
rebuilt in O(n) after each improving move. Works for asymmetric M (reversed segments use the
reversed arcs).

Two additions for large n (n > ``granular_above``), both switchable: granular neighbourhoods
(only moves that make a node adjacent to one of its K nearest nodes; Toth & Vigo 2003), which
make a scan O(n K) instead of O(n^2); and don't-look bits: after a perturbation only moves
anchored at nodes near its junctions (and near each applied move) are scanned. On the
Salehipour S200 instances these take the mean gap at 1 s from ~2-3% (full scans) to ~0.5-1%.
An optional threshold acceptance (``accept``) is available; the default is GILS-RVND's
improvement-only acceptance.

All kernels are numba ``@njit(cache=True)``: the first call in a fresh environment compiles
(a few seconds, cached on disk afterwards); call ``warm_up()`` outside timed code. Time limits
are enforced by the Python driver between chunks of ILS iterations; with ``time_limit=None``
the search is fully deterministic for a given seed. This module must not depend on OR-Tools.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numba
import numpy as np

from hiconav.exploration.wtrp.common import WTRPSolution, check_instance, check_order, wtrp_cost

_EPS = 1e-9

# ------------------------------------------------------------------------------------ kernels


@numba.njit(cache=True, nogil=True)
def _seed(seed: int) -> None:  # pragma: no cover - numba
    np.random.seed(seed)


@numba.njit(cache=True, nogil=True)
def _build(s, M, w, pos, pre):  # pragma: no cover - numba
    """Fill the O(n) prefix data of solution s (positions 0..N-1, s[0] = depot).

    pre[k, 0] = F_k: forward time from s[0] to s[k];  pre[k, 1] = R_k = sum_{m<k} M[s[m+1], s[m]]
    (reverse arcs); pre[k+1, 2] = sum_{m<=k} w(s[m]); pre[k+1, 3] = sum_{m<=k} w(s[m]) F_m;
    pre[k+1, 4] = sum_{m<=k} w(s[m]) R_m. pos[v] = position of node v.
    """
    N = s.shape[0]
    pre[0, 0] = 0.0
    pre[0, 1] = 0.0
    pre[0, 2] = 0.0
    pre[0, 3] = 0.0
    pre[0, 4] = 0.0
    for k in range(N):
        v = s[k]
        pos[v] = k
        if k > 0:
            pre[k, 0] = pre[k - 1, 0] + M[s[k - 1], v]
            pre[k, 1] = pre[k - 1, 1] + M[v, s[k - 1]]
        wk = w[v]
        pre[k + 1, 2] = pre[k, 2] + wk
        pre[k + 1, 3] = pre[k, 3] + wk * pre[k, 0]
        pre[k + 1, 4] = pre[k, 4] + wk * pre[k, 1]


@numba.njit(cache=True, nogil=True, inline="always")
def _cat(t1, c1, last1, s, M, pre, i, j):  # pragma: no cover - numba
    """Append segment (i, j) of s to an accumulated prefix (duration t1, latency c1, last node):
    forward s[i..j] if i <= j, else reversed s[i], s[i-1], ..., s[j]. Eq.: C(s1 + s2) =
    C1 + W2 (T1 + d) + C2 with the segment's (T2, C2, W2) from the prefix data in O(1)."""
    if i <= j:
        t2 = pre[j, 0] - pre[i, 0]
        w2 = pre[j + 1, 2] - pre[i, 2]
        c2 = (pre[j + 1, 3] - pre[i, 3]) - w2 * pre[i, 0]
    else:
        t2 = pre[i, 1] - pre[j, 1]
        w2 = pre[i + 1, 2] - pre[j, 2]
        c2 = w2 * pre[i, 1] - (pre[i + 1, 4] - pre[j, 4])
    d = t1 + M[last1, s[i]]
    return d + t2, c1 + w2 * d + c2, s[j]


@numba.njit(cache=True, nogil=True, inline="always")
def _eval_swap(s, M, pre, i, j):  # pragma: no cover - numba
    """Cost after swapping positions i < j."""
    n = s.shape[0] - 1
    t, c, last = pre[i - 1, 0], pre[i, 3], s[i - 1]
    t, c, last = _cat(t, c, last, s, M, pre, j, j)
    if j == i + 1:
        t, c, last = _cat(t, c, last, s, M, pre, i, i)
    else:
        t, c, last = _cat(t, c, last, s, M, pre, i + 1, j - 1)
        t, c, last = _cat(t, c, last, s, M, pre, i, i)
    if j < n:
        t, c, last = _cat(t, c, last, s, M, pre, j + 1, n)
    return c


@numba.njit(cache=True, nogil=True, inline="always")
def _eval_2opt(s, M, pre, i, j):  # pragma: no cover - numba
    """Cost after reversing positions i..j (i < j)."""
    n = s.shape[0] - 1
    t, c, last = pre[i - 1, 0], pre[i, 3], s[i - 1]
    t, c, last = _cat(t, c, last, s, M, pre, j, i)
    if j < n:
        t, c, last = _cat(t, c, last, s, M, pre, j + 1, n)
    return c


@numba.njit(cache=True, nogil=True, inline="always")
def _eval_oropt(s, M, pre, i, e, p):  # pragma: no cover - numba
    """Cost after moving block i..e between positions p and p+1 (p < i-1 or p > e)."""
    n = s.shape[0] - 1
    if p < i:
        t, c, last = pre[p, 0], pre[p + 1, 3], s[p]
        t, c, last = _cat(t, c, last, s, M, pre, i, e)
        t, c, last = _cat(t, c, last, s, M, pre, p + 1, i - 1)
        if e < n:
            t, c, last = _cat(t, c, last, s, M, pre, e + 1, n)
    else:
        t, c, last = pre[i - 1, 0], pre[i, 3], s[i - 1]
        t, c, last = _cat(t, c, last, s, M, pre, e + 1, p)
        t, c, last = _cat(t, c, last, s, M, pre, i, e)
        if p < n:
            t, c, last = _cat(t, c, last, s, M, pre, p + 1, n)
    return c


@numba.njit(cache=True, nogil=True, inline="always")
def _activate(s, active, a, b):  # pragma: no cover - numba
    """Mark the nodes at positions a..b (clipped) active (don't-look bits off)."""
    n = s.shape[0] - 1
    for p in range(max(0, a), min(n, b) + 1):
        active[s[p]] = True


@numba.njit(cache=True, nogil=True)
def _best_swap(s, M, pre, pos, nbr, full, active):  # pragma: no cover - numba
    N = s.shape[0]
    n = N - 1
    cur = pre[N, 3]
    best, bi, bj = cur - _EPS * (1.0 + abs(cur)), -1, -1
    if full:
        for i in range(1, n):
            for j in range(i + 1, n + 1):
                c = _eval_swap(s, M, pre, i, j)
                if c < best:
                    best, bi, bj = c, i, j
    else:  # granular: swaps that put s[i] next to one of its near neighbours
        K = nbr.shape[1]
        for i in range(1, n + 1):
            if not active[s[i]]:
                continue
            for q in range(K):
                qp = pos[nbr[s[i], q]]
                for j in (qp - 1, qp + 1):
                    if j < 1 or j > n or j == i:
                        continue
                    a, b = (i, j) if i < j else (j, i)
                    c = _eval_swap(s, M, pre, a, b)
                    if c < best:
                        best, bi, bj = c, a, b
    if bi >= 0:
        tmp = s[bi]
        s[bi] = s[bj]
        s[bj] = tmp
        _activate(s, active, bi - 1, bi + 1)
        _activate(s, active, bj - 1, bj + 1)
        return True
    return False


@numba.njit(cache=True, nogil=True)
def _best_2opt(s, M, pre, pos, nbr, full, active):  # pragma: no cover - numba
    N = s.shape[0]
    n = N - 1
    cur = pre[N, 3]
    best, bi, bj = cur - _EPS * (1.0 + abs(cur)), -1, -1
    if full:
        for i in range(1, n):
            for j in range(i + 2, n + 1):  # j = i + 1 is an adjacent swap
                c = _eval_2opt(s, M, pre, i, j)
                if c < best:
                    best, bi, bj = c, i, j
    else:  # granular: reversals that make s[x] and s[y] adjacent, y a near neighbour of x
        K = nbr.shape[1]
        for a in range(n + 1):
            if not active[s[a]]:
                continue
            for q in range(K):
                b = pos[nbr[s[a], q]]
                if b == 0 or abs(b - a) < 2:
                    continue
                x, y = (a, b) if a < b else (b, a)
                # reverse x+1..y -> edge (s[x], s[y]);  reverse x..y-1 -> edge (s[x], s[y])
                c = _eval_2opt(s, M, pre, x + 1, y)
                if c < best:
                    best, bi, bj = c, x + 1, y
                if x >= 1:
                    c = _eval_2opt(s, M, pre, x, y - 1)
                    if c < best:
                        best, bi, bj = c, x, y - 1
    if bi >= 0:
        s[bi:bj + 1] = s[bi:bj + 1][::-1].copy()
        _activate(s, active, bi - 1, bi)
        _activate(s, active, bj, bj + 1)
        return True
    return False


@numba.njit(cache=True, nogil=True)
def _best_oropt(s, M, pre, pos, nbr, full, k, active):  # pragma: no cover - numba
    """Move block s[i .. i+k-1] between positions p and p+1 (p outside the block)."""
    N = s.shape[0]
    n = N - 1
    cur = pre[N, 3]
    best, bi, bp = cur - _EPS * (1.0 + abs(cur)), -1, -1
    K = nbr.shape[1]
    for i in range(1, n - k + 2):
        e = i + k - 1
        if full:
            for p in range(n + 1):
                if p >= i - 1 and p <= e:
                    continue
                c = _eval_oropt(s, M, pre, i, e, p)
                if c < best:
                    best, bi, bp = c, i, p
        else:  # granular: insert right after a neighbour of s[i] or right before one of s[e]
            if not (active[s[i]] or active[s[e]] or active[s[i - 1]] or (e < n and active[s[e + 1]])):
                continue
            for q in range(K):
                for side in range(2):
                    if side == 0:
                        p = pos[nbr[s[i], q]]
                    else:
                        p = pos[nbr[s[e], q]] - 1
                    if p < 0 or (p >= i - 1 and p <= e):
                        continue
                    c = _eval_oropt(s, M, pre, i, e, p)
                    if c < best:
                        best, bi, bp = c, i, p
    if bi >= 0:
        block = s[bi:bi + k].copy()
        if bp < bi:
            s[bp + 1 + k:bi + k] = s[bp + 1:bi].copy()
            s[bp + 1:bp + 1 + k] = block
            _activate(s, active, bp, bp + k + 1)
            _activate(s, active, bi + k - 1, bi + k)
        else:
            s[bi:bp + 1 - k] = s[bi + k:bp + 1].copy()
            s[bp + 1 - k:bp + 1] = block
            _activate(s, active, bp - k, bp + 1)
            _activate(s, active, bi - 1, bi)
        return True
    return False


@numba.njit(cache=True, nogil=True)
def _rvnd(s, M, w, pos, pre, nbr, full, active):  # pragma: no cover - numba
    """Random variable neighbourhood descent; returns the final cost (s modified in place).

    Granular mode scans only moves anchored at active nodes (don't-look bits: the caller
    activates the nodes around a perturbation's junctions; every applied move activates the
    nodes at its new edges); all bits are cleared when the descent ends."""
    n = s.shape[0] - 1
    _build(s, M, w, pos, pre)
    if n < 2:
        return pre[n + 1, 3]
    nl = np.arange(5)
    size = 5
    while size > 0:
        r = np.random.randint(size)
        kind = nl[r]
        if kind == 0:
            improved = _best_swap(s, M, pre, pos, nbr, full, active)
        elif kind == 1:
            improved = _best_2opt(s, M, pre, pos, nbr, full, active)
        else:
            k = kind - 1  # or-opt 1, 2, 3
            improved = _best_oropt(s, M, pre, pos, nbr, full, k, active) if k < n else False
        if improved:
            _build(s, M, w, pos, pre)
            size = 5
            for q in range(5):
                nl[q] = q
        else:
            nl[r] = nl[size - 1]
            nl[size - 1] = kind
            size -= 1
    active[:] = False
    return pre[n + 1, 3]


@numba.njit(cache=True, nogil=True)
def _construct(M, w, alpha):  # pragma: no cover - numba
    """Randomized greedy: pick among the ceil(alpha |CL|) best candidates by M[cur, c] / w_c."""
    N = M.shape[0]
    s = np.empty(N, dtype=np.int64)
    s[0] = 0
    cand = np.arange(1, N)
    m = N - 1
    cur = 0
    key = np.empty(N - 1)
    for pos in range(1, N):
        for q in range(m):
            c = cand[q]
            key[q] = M[cur, c] / w[c] if w[c] > 0 else 1e300 + M[cur, c]
        rcl = max(1, int(math.ceil(alpha * m)))  # noqa: RUF046 (numba)
        idx = np.argsort(key[:m])
        q = idx[np.random.randint(rcl)]
        cur = cand[q]
        s[pos] = cur
        cand[q] = cand[m - 1]
        m -= 1
    return s


@numba.njit(cache=True, nogil=True)
def _double_bridge(s, lmax, active):  # pragma: no cover - numba
    """Exchange two random non-overlapping segments of lengths in [1, lmax]; activate the nodes
    around the new junctions."""
    n = s.shape[0] - 1
    out = s.copy()
    if n < 4:
        i = 1 + np.random.randint(n)
        j = 1 + np.random.randint(n)
        out[i], out[j] = s[j], s[i]
        active[:] = True
        return out
    lmax = max(1, min(lmax, (n - 1) // 2))
    l1 = 1 + np.random.randint(lmax)
    l2 = 1 + np.random.randint(lmax)
    i = 1 + np.random.randint(n - l1 - l2 + 1)          # seg1 = [i, i+l1)
    j = i + l1 + np.random.randint(n - l2 + 2 - (i + l1))  # seg2 = [j, j+l2), j <= n - l2 + 1
    q = i
    for v in s[j:j + l2]:
        out[q] = v
        q += 1
    for v in s[i + l1:j]:
        out[q] = v
        q += 1
    for v in s[i:i + l1]:
        out[q] = v
        q += 1
    mid = j - (i + l1)
    for p in (i, i + l2, i + l2 + mid, j + l2):  # first position after each junction
        _activate(out, active, p - 2, p + 1)
    return out


@numba.njit(cache=True, nogil=True)
def _ils_chunk(M, w, best, best_cost, cur, cur_cost, no_improve, max_no_improve, iters, pos, pre, nbr, full,
               lmax, active, dont_look, accept):  # pragma: no cover - numba
    """Up to ``iters`` ILS iterations: perturb the current solution ``cur``, descend, keep the
    best of this start in ``best`` (both modified in place). Acceptance: a better solution, or
    (accept > 0) any within (1 + accept) of the best (threshold acceptance). Returns
    (best_cost, cur_cost, no_improve, iterations done)."""
    done = 0
    while done < iters and no_improve < max_no_improve:
        s = _double_bridge(cur, lmax, active)
        if not dont_look:
            active[:] = True
        c = _rvnd(s, M, w, pos, pre, nbr, full, active)
        done += 1
        if c < best_cost - _EPS * (1.0 + abs(best_cost)):
            best[:] = s
            best_cost = c
            cur[:] = s
            cur_cost = c
            no_improve = 0
        else:
            no_improve += 1
            if c < cur_cost - _EPS * (1.0 + abs(cur_cost)) or c <= best_cost * (1.0 + accept):
                cur[:] = s
                cur_cost = c
    return best_cost, cur_cost, no_improve, done


@numba.njit(cache=True, nogil=True)
def _start(M, w, alpha, pos, pre, nbr, full, active):  # pragma: no cover - numba
    s = _construct(M, w, alpha)
    active[:] = True
    c = _rvnd(s, M, w, pos, pre, nbr, full, active)
    return s, c


# ------------------------------------------------------------------------------------ driver

_ALPHAS = np.arange(26) / 100.0  # GILS-RVND's R = {0.00, 0.01, ..., 0.25}


def warm_up() -> None:
    """Compile (or load from the numba cache) every kernel on a tiny instance."""
    rng = np.random.default_rng(0)
    xy = rng.random((8, 2))
    M = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
    solve_ils(M, np.ones(7), time_limit=None, max_restarts=1, seed=0)


def solve_ils(M: np.ndarray, W: np.ndarray, *, time_limit: float | None = 1.0, seed: int = 0,
              max_restarts: int = 10, ils_iters: int = 100, neighbours: int = 15,
              granular_above: int = 30, perturb_len: int = 0, dont_look: bool = True,
              accept: float = 0.0, target_cost: float | None = None,
              clock: Callable[[], float] = time.perf_counter) -> WTRPSolution:
    """GILS-RVND for the weighted latency (see module docstring).

    M: (n+1, n+1) costs, node 0 the robot; W: (n,) weights of nodes 1..n.
    time_limit: wall seconds (checked between chunks of ILS iterations; overshoot is at most one
      RVND descent); None = no limit, deterministic for a seed. The search stops at the first of
      time limit, ``max_restarts`` completed starts, or reaching ``target_cost`` (benchmarks).
    ils_iters: I_ILS cap, perturbations without improvement before a restart (min(n, ils_iters)).
    neighbours, granular_above: for n > granular_above the neighbourhoods are granular: only
      moves that make a node adjacent to one of its ``neighbours`` nearest nodes (by M + M^T)
      are evaluated (O(n K) per scan instead of O(n^2)); smaller n scans everything.
    perturb_len: longest double-bridge segment (0: GILS-RVND's n / 10).
    dont_look: granular mode only: after a perturbation, scan only moves anchored near its
      junctions and near applied moves (don't-look bits); False rescans every node.
    accept: threshold acceptance: a perturbed-and-descended solution within (1 + accept) of the
      start's best becomes the current one (0: only improvements, as GILS-RVND).
    clock: the clock of ``time_limit``; time.process_time measures this process's CPU time,
      which on a loaded machine approximates the wall time of a quiet one (benchmarks only).
    """
    t0 = time.perf_counter()
    c0 = clock()
    M, w = check_instance(M, W)
    n = M.shape[0] - 1
    if n <= 1:
        order = tuple(range(1, n + 1))
        return WTRPSolution(order, wtrp_cost(M, w[1:], order), "ils", time.perf_counter() - t0)
    deadline = math.inf if time_limit is None else c0 + time_limit
    rng = np.random.default_rng(seed)
    _seed(int(rng.integers(2**31 - 1)))
    N = n + 1
    pos, pre = np.empty(N, dtype=np.int64), np.empty((N + 1, 5))
    full = n <= granular_above
    active = np.zeros(N, dtype=np.bool_)
    lmax = max(1, n // 10) if perturb_len <= 0 else perturb_len  # GILS-RVND: n / 10
    K = max(1, min(neighbours, n))
    sym = M + M.T
    np.fill_diagonal(sym, np.inf)
    nbr = np.ascontiguousarray(np.argsort(sym, axis=1, kind="stable")[:, :K].astype(np.int64))
    max_no_improve = max(1, min(n, ils_iters))
    best_s, best_c = None, math.inf
    chunk = 1
    for _restart in range(max_restarts):
        alpha = float(_ALPHAS[rng.integers(len(_ALPHAS))])
        s, c = _start(M, w, alpha, pos, pre, nbr, full, active)
        cur, cur_c = s.copy(), c
        no_improve = 0
        while no_improve < max_no_improve:
            if clock() >= deadline or (target_cost is not None and c <= target_cost):
                break
            tc = clock()
            c, cur_c, no_improve, done = _ils_chunk(M, w, s, c, cur, cur_c, no_improve, max_no_improve, chunk,
                                                     pos, pre, nbr, full, lmax, active, dont_look, accept)
            # aim at ~10 ms per chunk so the time limit is honoured closely
            el = clock() - tc
            if time_limit is not None:
                per = el / max(done, 1)
                chunk = int(max(1, min(1000, 0.01 / max(per, 1e-7))))
            else:
                chunk = max_no_improve
        if c < best_c:
            best_s, best_c = s.copy(), c
        if clock() >= deadline or (target_cost is not None and best_c <= target_cost):
            break
    order = tuple(int(v) for v in best_s[1:])
    check_order(order, n)
    return WTRPSolution(order, wtrp_cost(M, w[1:], order), "ils", time.perf_counter() - t0)
