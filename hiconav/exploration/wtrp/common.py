"""Shared pieces of the Weighted Traveling Repairman (WTRP) solvers: input checks, the
objective (paper eq. "min sum_i W_pi(i) C_i(pi)") and the solution type.

Conventions (all solvers): ``M`` is an (n+1, n+1) float cost matrix, node 0 is the robot (the
depot), nodes 1..n are the candidates; the path is open (``M[k, 0]`` is never used). ``W`` is
the (n,) weight of nodes 1..n (``W[i-1]`` belongs to node i). An order is a permutation of
1..n. This module must not import a solver backend (numba, OR-Tools).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiconav.errors import HiconavError


class WTRPError(HiconavError):
    """Invalid WTRP input (matrix shape, weights, method name)."""


@dataclass(frozen=True)
class WTRPSolution:
    """A visiting order of nodes 1..n, its weighted latency, the solver and its wall time (s)."""

    order: tuple[int, ...]
    cost: float
    method: str
    seconds: float


def check_instance(M: np.ndarray, W: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Validate and convert: returns (M (n+1, n+1) float64 C-contiguous, w (n+1,) float64 with
    w[0] = 0). Raises WTRPError naming the field that is wrong."""
    M = np.ascontiguousarray(M, dtype=np.float64)
    W = np.asarray(W, dtype=np.float64).reshape(-1)
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise WTRPError(f"cost matrix must be square (n+1, n+1), got shape {M.shape}", field="M")
    n = M.shape[0] - 1
    if n < 0:
        raise WTRPError("cost matrix is empty; node 0 (the robot) is required", field="M")
    if W.shape[0] != n:
        raise WTRPError(f"weights must have n = {n} entries (nodes 1..n), got {W.shape[0]}", field="W")
    if not np.all(np.isfinite(M)):
        raise WTRPError("cost matrix has NaN or inf entries; drop unreachable nodes first", field="M")
    if not np.all(np.isfinite(W)) or np.any(W < 0):
        raise WTRPError("weights must be finite and >= 0", field="W")
    if np.any(M < 0):
        raise WTRPError("cost matrix entries must be >= 0", field="M")
    w = np.zeros(n + 1, dtype=np.float64)
    w[1:] = W
    return M, w


def wtrp_cost(M: np.ndarray, W: np.ndarray, order: tuple[int, ...] | np.ndarray) -> float:
    """Weighted latency sum_i W_pi(i) * C_i(pi) of an open path 0 -> order[0] -> ... (eq. 14, 15).

    ``order`` may be a prefix of a permutation (unvisited nodes contribute nothing).
    """
    M = np.asarray(M, dtype=np.float64)
    W = np.asarray(W, dtype=np.float64)
    path = np.concatenate([[0], np.asarray(order, dtype=np.int64)])
    if path.size == 1:
        return 0.0
    arrival = np.cumsum(M[path[:-1], path[1:]])  # C_i, eq. 14
    return float(np.dot(W[path[1:] - 1], arrival))


def check_order(order: tuple[int, ...], n: int) -> None:
    """Raise WTRPError unless ``order`` is a permutation of 1..n (a solver self-check)."""
    if sorted(order) != list(range(1, n + 1)):
        raise WTRPError(f"solver returned an order that is not a permutation of 1..{n}: {order}")
