"""The room prior: counts of categories per room type learnt from training houses, their
likelihood ratios, the shipped file and its command line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from hiconav.cli import main as cli_main
from hiconav.reasoning import room_prior
from hiconav.reasoning.grounding import infer_rooms
from hiconav.reasoning.room_prior import RoomPrior, from_json, load, log_ratios

from .helpers import houses_elsewhere
from .test_grounding import node

SHARED = Path(__file__).resolve().parents[3] / "shared" / "data" / "procthor" / "train.jsonl.gz"


def test_likelihood_ratios_favour_the_rooms_a_category_stands_in_and_skip_rare_categories():
    prior = RoomPrior({"bed": {"bedroom": 30}, "sink": {"bathroom": 20}, "sofa": {"living_room": 20},
                       "chair": {"bedroom": 10, "kitchen": 10}, "rare": {"kitchen": 3}})
    lr = log_ratios(prior, min_count=10)
    assert "rare" not in lr
    assert max(lr["bed"], key=lr["bed"].get) == "bedroom"
    assert lr["sink"]["bathroom"] > 0 > lr["sink"]["bedroom"]
    assert all(math.isfinite(v) for v in lr["bed"].values())  # smoothed: no room is impossible
    # a chair seen as often in bedrooms as in kitchens says little of either
    assert abs(lr["chair"]["bedroom"] - lr["chair"]["kitchen"]) < abs(lr["bed"]["bedroom"] - lr["bed"]["kitchen"])


def test_the_posterior_follows_the_cues_and_stays_unknown_when_they_disagree():
    cues = {"bed": {"bedroom": 2.0, "kitchen": -2.0}, "fridge": {"kitchen": 2.0, "bedroom": -2.0}}
    bed = node(1, "bed", (0, 0), anchors=(1,))
    fridge = node(2, "fridge", (0.8, 0), anchors=(1,))
    room, p = infer_rooms([bed], cues=cues)[1]
    assert room == "bedroom" and 0.6 <= p < 1.0
    assert infer_rooms([bed, fridge], cues=cues)[1][0] is None  # one cue each way, side by side


def test_the_shipped_prior_says_what_the_training_houses_say():
    lr = room_prior.default_log_ratios()
    for category, room in [("bed", "bedroom"), ("toilet", "bathroom"), ("fridge", "kitchen"),
                           ("sofa", "living_room"), ("sink", "bathroom")]:
        assert max(lr[category], key=lr[category].get) == room, category
    # in ProcTHOR an armchair or floor lamp stands in a bedroom about as often as in a living
    # room: alone with one, the map does not claim to know the room
    scene = [node(1, "armchair", (0, 0), anchors=(1,)), node(2, "floor_lamp", (0.9, 0), (0.3, 0.3), anchors=(1,))]
    assert infer_rooms(scene)[1][0] is None
    assert load().source == "train.jsonl.gz"  # learnt on training houses only


def test_a_broken_prior_file_is_named_with_its_field(tmp_path):
    with pytest.raises(ValueError, match=r"counts\.bed\.attic: unknown room type"):
        from_json({"counts": {"bed": {"attic": 3}}}, "p.json")
    with pytest.raises(ValueError, match=r"counts\.bed\.bedroom: expected a count"):
        from_json({"counts": {"bed": {"bedroom": -1}}}, "p.json")
    with pytest.raises(ValueError, match="expected an object with a 'counts'"):
        from_json([], "p.json")
    bad = tmp_path / "prior.json"
    bad.write_text('{"counts": {\n  "bed": }')
    with pytest.raises(ValueError, match=r"prior\.json: line 2: not JSON"):
        load(bad)
    with pytest.raises(ValueError, match="no object counted"):
        RoomPrior({}, "empty").room_shares()


@pytest.mark.skipif(not SHARED.is_file(), reason="needs ../shared/data/procthor/train.jsonl.gz")
def test_the_command_learns_from_a_houses_file_anywhere_and_round_trips(tmp_path, capsys):
    houses = houses_elsewhere(SHARED, tmp_path, 2, "two.jsonl.gz")
    out = tmp_path / "prior.json"
    assert cli_main(["room-prior", "--houses", str(houses), "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    prior = load(out)
    assert prior.source == "two.jsonl.gz" and summary["categories"] == len(prior.counts) > 0
    assert summary["objects"] == sum(sum(c.values()) for c in prior.counts.values())
    assert load(out) == prior  # what is written reads back the same
    shipped = load()
    # two of the hundred training houses: never more of a category than all of them hold
    for cat, counts in prior.counts.items():
        for room, n in counts.items():
            assert n <= shipped.counts[cat].get(room, 0), (cat, room)


def test_a_users_own_prior_file_anywhere_decides_the_rooms_and_a_bad_one_names_the_setting(tmp_path):
    from hiconav.reasoning.config import ReasoningConfig
    from hiconav.reasoning.verifier import OfflineVerifier

    from .test_grounding import TASK, _living_room_scene, graph

    scene = graph(_living_room_scene())  # armchair #1 by a floor lamp, a sofa in view
    shipped = OfflineVerifier(ReasoningConfig()).verify(scene, TASK)
    assert shipped.found and shipped.hypothesis.object_id == 1
    # houses of the user's own where sofas stand in bedrooms
    path = tmp_path / "elsewhere" / "my_prior.json"
    path.parent.mkdir()
    room_prior.save(RoomPrior({"sofa": {"bedroom": 50}, "bed": {"living_room": 50},
                               "fridge": {"kitchen": 50}, "toilet": {"bathroom": 50}}, "mine"), path)
    config = ReasoningConfig.model_validate({"offline": {"room_prior": str(path)}})
    mine = OfflineVerifier(config).verify(scene, TASK)
    assert not mine.found and mine.verdicts[1] == "fails"
    missing = ReasoningConfig.model_validate({"offline": {"room_prior": str(tmp_path / "nope.json")}})
    with pytest.raises(ValueError, match=r"reasoning\.offline\.room_prior: .*nope\.json"):
        OfflineVerifier(missing)


def test_the_command_names_a_houses_file_it_cannot_read(tmp_path, capsys):
    assert cli_main(["room-prior", "--houses", str(tmp_path / "nope.jsonl.gz"), "--out", str(tmp_path / "p.json")]) == 2
    assert "nope.jsonl.gz" in capsys.readouterr().err
    bad = tmp_path / "bad.jsonl"
    bad.write_text('{"rooms": [\n')
    assert cli_main(["room-prior", "--houses", str(bad), "--out", str(tmp_path / "p.json")]) == 2
    assert "bad.jsonl:1" in capsys.readouterr().err
    assert not (tmp_path / "p.json").exists()  # nothing half-written
