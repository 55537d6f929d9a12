"""Rescoring a finished run's SPL with l^s measured to the success region."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.eval.records import EpisodeRecord, dumps
from hiconav.eval.rescore import main, rescore
from hiconav.eval.sources import procthor_source, write_specs


def test_a_run_scored_against_the_object_distance_is_rescored_to_the_success_region(shared_data, tmp_path,
                                                                                       capsys) -> None:
    from hiconav.sim.geodesic import GoalDistance

    specs = procthor_source(shared_data / "procthor" / "val.jsonl.gz", 1, seed=0, limit=2)
    write_specs(tmp_path / "specs.jsonl", specs)
    # episode 0 "walked" exactly its distance to the object (SPL 1 under the old l^s), episode 1 failed
    l_obj = specs[0].geodesic_distance
    records = [EpisodeRecord(episode_id=specs[0].episode_id, house=specs[0].house, target=specs[0].target,
                             success=True, spl=1.0, path_length=l_obj, failure="success"),
               EpisodeRecord(episode_id=specs[1].episode_id, house=specs[1].house, target=specs[1].target,
                             success=False, spl=0.0, path_length=3.0, failure="step_out")]
    (tmp_path / "episodes.jsonl").write_text("".join(dumps(r) + "\n" for r in records))
    goal = GoalDistance(specs[0].load_house(), instance_ids=list(specs[0].goal_instance_ids))
    l_s = goal.to_success(np.asarray(specs[0].start[:2]), 1.0)
    # shorter, by the success distance at most (and by up to 8% more: l_s is any-angle, l_obj cell paths)
    assert 0.92 * (l_obj - 1.0) <= l_s < l_obj
    n, sr, old, new = rescore(tmp_path)["full"]
    assert (n, sr, old) == (2, 0.5, 0.5)
    assert new == pytest.approx(0.5 * l_s / l_obj)
    assert main([str(tmp_path)]) == 0
    assert "SPL to the success region" in capsys.readouterr().out


def test_a_folder_without_a_run_is_refused_with_the_file_named(tmp_path, capsys) -> None:
    assert main([str(tmp_path / "nothing")]) == 2
    assert "specs.jsonl" in capsys.readouterr().err
