"""Weighted set multicover (eqs. 5-7): exact ILP, the r_j rule, reductions, labelled fallback."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.sparse as sp

import hiconav.memory.setcover as sc
from hiconav.memory.setcover import (
    SetCoverError,
    greedy_multicover,
    is_feasible_cover,
    multicover_requirements,
    read_orlib,
    solve_multicover,
)


def random_instance(rng: np.random.Generator, m: int, n: int, r: int, density: float = 0.35):
    A = (rng.random((m, n)) < density).astype(float)
    for j in range(m):  # every row covered at least once
        if A[j].sum() == 0:
            A[j, rng.integers(n)] = 1.0
    costs = rng.integers(1, 10, size=n).astype(float)
    A = sp.csr_matrix(A)
    return costs, A, multicover_requirements(A, r)


def brute_force(costs: np.ndarray, A: sp.csr_matrix, req: np.ndarray) -> float:
    n = A.shape[1]
    dense = A.toarray()
    best = np.inf
    for bits in itertools.product((0, 1), repeat=n):
        x = np.array(bits, float)
        if np.all(dense @ x >= req):
            best = min(best, float(costs @ x))
    return best


def test_r_j_is_min_of_r_and_degree():
    # eq. (7): rows covered by 1, 2 and 3 columns with r = 2
    A = sp.csr_matrix(np.array([[1, 0, 0], [1, 1, 0], [1, 1, 1]], float))
    assert multicover_requirements(A, 2).tolist() == [1, 2, 2]
    assert multicover_requirements(A, 1).tolist() == [1, 1, 1]
    assert multicover_requirements(A, 5).tolist() == [1, 2, 3]


@pytest.mark.parametrize("r", [1, 2, 3])
def test_ilp_equals_brute_force_on_random_multicover(r):
    rng = np.random.default_rng(100 + r)
    for _ in range(12):
        m, n = int(rng.integers(3, 9)), int(rng.integers(3, 11))
        costs, A, req = random_instance(rng, m, n, r)
        res = solve_multicover(costs, A, req, time_limit=5.0)
        assert res.proven_optimal
        assert res.status in ("optimal", "trivial")
        assert is_feasible_cover(A, req, np.array(res.selected))
        assert res.cost == pytest.approx(brute_force(costs, A, req))


def test_reductions_keep_the_optimum():
    rng = np.random.default_rng(7)
    for _ in range(10):
        costs, A, req = random_instance(rng, 15, 12, 2, density=0.3)
        a = solve_multicover(costs, A, req, reduce=True)
        b = solve_multicover(costs, A, req, reduce=False)
        assert a.cost == pytest.approx(b.cost)
        # pure set cover exercises the dominated-column test
        req1 = multicover_requirements(A, 1)
        assert solve_multicover(costs, A, req1).cost == pytest.approx(
            solve_multicover(costs, A, req1, reduce=False).cost)


def test_greedy_is_feasible_and_irredundant():
    rng = np.random.default_rng(3)
    costs, A, req = random_instance(rng, 30, 25, 2)
    sel = greedy_multicover(costs, A, req)
    assert is_feasible_cover(A, req, sel)
    for i in sel:  # redundancy removal: no selected column can be dropped
        assert not is_feasible_cover(A, req, np.setdiff1d(sel, [i]))


def test_requirement_above_degree_is_rejected_with_the_row():
    A = sp.csr_matrix(np.array([[1, 0], [1, 1]], float))
    with pytest.raises(SetCoverError, match=r"row 0 needs 2"):
        solve_multicover(np.ones(2), A, np.array([2, 1]))


def test_solver_failure_gives_labelled_greedy_fallback(monkeypatch):
    rng = np.random.default_rng(5)
    costs, A, req = random_instance(rng, 12, 10, 2)

    def broken(*args, **kwargs):
        raise RuntimeError("solver crashed")

    monkeypatch.setattr(sc, "_solve_mip", broken)
    res = solve_multicover(costs, A, req, reduce=False)
    assert res.status == "greedy-fallback" and res.is_fallback
    assert not res.proven_optimal
    assert "solver crashed" in res.message
    assert is_feasible_cover(A, req, np.array(res.selected))


def test_time_out_without_incumbent_gives_labelled_fallback(monkeypatch):
    rng = np.random.default_rng(6)
    costs, A, req = random_instance(rng, 12, 10, 2)

    timed_out = sc._MipOutcome(None, 1, "Time limit reached", None)
    monkeypatch.setattr(sc, "_solve_mip", lambda *a, **k: timed_out)
    res = solve_multicover(costs, A, req, reduce=False)
    assert res.status == "greedy-fallback"
    assert not res.proven_optimal
    assert is_feasible_cover(A, req, np.array(res.selected))


def test_orlib_reader_and_scp41_optimum(shared_data):
    inst = read_orlib(shared_data / "setcover" / "scp41.txt")
    assert (inst.n_rows, inst.n_columns) == (200, 1000)
    assert inst.cover.nnz > 0 and set(np.unique(inst.cover.data)) == {1.0}
    res = solve_multicover(inst.costs, inst.cover, inst.requirements, time_limit=30.0)
    assert res.proven_optimal
    assert res.cost == 429  # optimal.csv


def test_orlib_reader_names_the_file_on_truncation(tmp_path):
    p = tmp_path / "bad.txt"
    p.write_text("3 2\n1 1\n1 1\n2 1")
    with pytest.raises(Exception, match="bad.txt"):
        read_orlib(p)


def test_time_out_with_incumbent_is_reported_unproven(monkeypatch):
    A = sp.csr_matrix(np.array([[1, 1, 0], [0, 1, 1], [1, 0, 1]], float))
    req = multicover_requirements(A, 1)

    # feasible, cost 2 (optimum is 2 as well, but not proven)
    incumbent = sc._MipOutcome(np.array([1.0, 1.0, 0.0]), 1, "Time limit reached", 1.5)
    monkeypatch.setattr(sc, "_solve_mip", lambda *a, **k: incumbent)
    res = solve_multicover(np.array([1.0, 1.0, 1.0]) + [0, 0, 0.5], A, req, reduce=False)
    assert res.status == "time-limit" and not res.proven_optimal and not res.is_fallback
    assert res.selected == (0, 1) and res.lower_bound == 1.5


@pytest.mark.parametrize("r", [1, 2])
def test_fractional_costs_equal_brute_force(r):
    # non-integral costs: reduced-cost fixing must use delta = 0 (no "better by 1" slack)
    rng = np.random.default_rng(300 + r)
    for _ in range(10):
        m, n = int(rng.integers(4, 10)), int(rng.integers(6, 13))
        costs, A, req = random_instance(rng, m, n, r)
        costs = costs * rng.uniform(0.5, 1.5, n)
        res = solve_multicover(costs, A, req)
        assert res.proven_optimal
        assert res.cost == pytest.approx(brute_force(costs, A, req))
        assert res.lower_bound <= res.cost + 1e-9


def test_lagrangian_bound_from_lp_duals_is_a_lower_bound():
    rng = np.random.default_rng(11)
    for r in (1, 2):
        costs, A, req = random_instance(rng, 8, 10, r)
        u = sc._lp_duals(costs, A, req)
        assert u is not None and np.all(u >= 0)
        d = costs - A.T @ u
        lag = float(req @ u + np.minimum(d, 0).sum())
        assert lag <= brute_force(costs, A, req) + 1e-7


def test_mip_backends_agree_and_reduced_cost_fixing_keeps_the_optimum(monkeypatch):
    # mid-size instances where the heuristic rarely closes the gap, so fixing + MIP run
    rng = np.random.default_rng(21)
    instances = [random_instance(rng, 60, 80, r, density=0.08) for r in (1, 1, 2)]
    with_highspy = [solve_multicover(*inst) for inst in instances]
    plain = [solve_multicover(*inst, reduce=False) for inst in instances]
    monkeypatch.setattr(sc, "highspy", None)  # scipy.optimize.milp backend
    with_scipy = [solve_multicover(*inst) for inst in instances]
    for inst, a, b, c in zip(instances, with_highspy, plain, with_scipy):
        assert a.proven_optimal and b.proven_optimal and c.proven_optimal
        assert a.cost == pytest.approx(b.cost) and c.cost == pytest.approx(b.cost)
        assert is_feasible_cover(inst[1], inst[2], np.array(a.selected))


def test_time_out_after_fixing_keeps_a_feasible_labelled_fallback(monkeypatch):
    # reduce=True path (LP bound, heuristic incumbent, fixing) with a MIP that returns nothing
    rng = np.random.default_rng(21)
    costs, A, req = random_instance(rng, 60, 80, 1, density=0.08)
    optimum = solve_multicover(costs, A, req).cost
    timed_out = sc._MipOutcome(None, 1, "Time limit reached", None)
    monkeypatch.setattr(sc, "_solve_mip", lambda *a, **k: timed_out)
    res = solve_multicover(costs, A, req)
    assert res.status == "greedy-fallback" and not res.proven_optimal
    assert is_feasible_cover(A, req, np.array(res.selected))
    assert res.lower_bound is not None and res.lower_bound <= optimum + 1e-9 <= res.cost + 1e-9


def test_a_solve_prints_no_highs_banner() -> None:
    """HiGHS prints its copyright banner once per process, when the first Highs is built (before
    output_flag can be set): a fresh process solves one ILP and must print nothing."""
    import subprocess
    import sys

    script = (
        "import numpy as np, scipy.sparse as sp\n"
        "import hiconav.memory.setcover as sc\n"
        "assert sc.highspy is not None, 'highspy is a dependency'\n"
        "A = sp.csr_matrix(np.array([[1, 1, 0], [0, 1, 1], [1, 0, 1]], float))\n"
        "r = sc.solve_multicover(np.array([1.0, 2.0, 1.0]), A, np.ones(3))\n"
        "assert r.status == 'optimal', r.status\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "" and proc.stderr == "", (proc.stdout, proc.stderr)
