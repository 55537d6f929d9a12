"""The size prior (how large each category's objects are, learnt from training houses), and the
relations it keeps open on a memory box seen in part."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from hiconav.cli import main as cli_main
from hiconav.reasoning import size_prior
from hiconav.reasoning.grounding import could_hold, ground, grown_toward
from hiconav.reasoning.size_prior import SizePrior, from_json, learn, load

from .helpers import houses_elsewhere
from .test_grounding import node

SHARED = Path(__file__).resolve().parents[3] / "shared" / "data" / "procthor" / "train.jsonl.gz"
SIZES = {"bed": (2.0, 1.4), "chair": (0.55, 0.5), "dining_table": (1.7, 1.0), "laptop": (0.35, 0.28),
         "painting": (0.8, 0.03)}
UNDER = [("bed", "under", "painting")]


def _obj(category, size, default=False):
    return SimpleNamespace(category=category, size=np.array(size, float), default_size=default)


def test_the_prior_takes_each_category_median_sides_and_skips_fallback_sizes_and_rare_categories():
    houses = [SimpleNamespace(objects=[_obj("bed", (1.0, 2.0, 0.6)), _obj("bed", (2.2, 1.4, 0.6)),
                                       _obj("bed", (2.0, 1.2, 0.5)), _obj("bed", (9.0, 9.0, 1.0), default=True),
                                       _obj("vase", (0.2, 0.2, 0.3))])]
    prior = learn(houses, source="mine", min_count=2)
    assert prior.sizes["bed"] == pytest.approx((2.0, 1.2))  # long sides 2.0, 2.2, 2.0; short 1.0, 1.4, 1.2
    assert prior.counts["bed"] == 3 and "vase" not in prior.sizes  # one vase: no size


def test_the_shipped_prior_says_what_the_training_houses_say():
    sizes = size_prior.default_sizes()
    assert sizes["bed"][0] > 1.8 and sizes["bed"][1] > 1.0
    assert sizes["chair"][0] < 0.8 and sizes["painting"][1] < 0.1  # a painting is thin
    assert sizes["counter_top"][0] > sizes["dining_table"][0] > sizes["chair"][0]
    assert load().source == "train.jsonl.gz"  # learnt on training houses only


def test_a_broken_size_file_is_named_with_its_field(tmp_path):
    with pytest.raises(ValueError, match=r"sizes\.bed\.long: expected a length"):
        from_json({"sizes": {"bed": {"long": "big", "short": 1.0}}}, "s.json")
    with pytest.raises(ValueError, match=r"sizes\.bed: 'short' \(2\.0\) is longer"):
        from_json({"sizes": {"bed": {"long": 1.0, "short": 2.0}}}, "s.json")
    with pytest.raises(ValueError, match="expected an object with a 'sizes'"):
        from_json([], "s.json")
    bad = tmp_path / "sizes.json"
    bad.write_text('{"sizes": {\n  "bed": }')
    with pytest.raises(ValueError, match=r"sizes\.json: line 2: not JSON"):
        load(bad)
    good = tmp_path / "elsewhere" / "mine.json"
    good.parent.mkdir()
    size_prior.save(SizePrior({"bed": (2.0, 1.4)}, {"bed": 7}, "mine"), good)
    assert load(good) == SizePrior({"bed": (2.0, 1.4)}, {"bed": 7}, "mine")


def test_a_box_narrower_than_its_kind_grows_toward_the_other_object_to_its_short_side():
    counter = node(1, "counter_top", (0.0, 0.0), (1.9, 0.05), (0.0, 0.9))  # a counter seen edge-on
    painting = node(2, "painting", (0.0, 1.6), (0.8, 0.03), (1.2, 1.8))  # on the wall to the north
    sizes = {"counter_top": (2.4, 1.2)}
    grown = grown_toward(counter, painting, sizes["counter_top"])
    assert grown.box_max[1] == pytest.approx(0.025 + 1.15) and grown.box_min[1] == pytest.approx(-0.025)
    assert grown.box_min[0] == pytest.approx(-0.95) and grown.box_max[0] == pytest.approx(0.95)  # wide enough
    south = node(3, "painting", (0.0, -1.6), (0.8, 0.03), (1.2, 1.8))
    assert grown_toward(counter, south, sizes["counter_top"]).box_min[1] == pytest.approx(-0.025 - 1.15)
    whole = node(4, "counter_top", (0.0, 0.0), (2.4, 1.1), (0.0, 0.9))
    assert grown_toward(whole, painting, sizes["counter_top"]) is None  # within 0.2 m of its size
    assert grown_toward(counter, painting, None) is None  # a category with no size


def test_a_relation_failing_on_a_related_object_seen_in_part_is_unknown_not_failed():
    """"The painting next to the counter": the counter seen edge-on, its box 2 cm deep and 1.6 m
    from the painting on the wall; the whole counter, a metre deep, would stand 0.6 m from it.
    What the robot saw does not rule the painting out; the same gap to a counter seen whole, or
    a candidate's own thin box, does."""
    sizes = {"counter_top": (2.4, 1.2), "painting": (0.8, 0.03)}
    painting = node(1, "painting", (0.0, 1.7), (0.8, 0.03), (1.2, 1.8))
    edge_on = node(2, "counter_top", (0.0, 0.0), (1.9, 0.02), (0.0, 0.9))
    beside = [("painting", "next to", "counter_top")]
    verdict = ground(painting, [painting, edge_on], beside, ["painting"], rooms={}, sizes=sizes)
    assert verdict.status == "unknown", verdict.evidence
    assert "seen in part" in verdict.evidence[0]
    whole = node(2, "counter_top", (0.0, -0.55), (1.9, 1.2), (0.0, 0.9))  # far edge 1.6 m from it
    assert ground(painting, [painting, whole], beside, ["painting"], rooms={}, sizes=sizes).status == "fails"
    # without sizes (or with none for the category) the boxes decide as they are
    assert ground(painting, [painting, edge_on], beside, ["painting"], rooms={}, sizes={}).status == "fails"
    # only the related object grows: a bed seen edge-on 1.6 m from the wall stays ruled out
    bed = node(3, "bed", (0.0, 0.0), (1.9, 0.05), (0.0, 0.6))
    verdict = ground(bed, [bed, painting], UNDER, ["bed"], rooms={}, sizes=SIZES)
    assert verdict.status == "fails", verdict.evidence


def test_a_related_object_seen_in_part_keeps_the_relation_open():
    """"The laptop on the dining table": a table seen along its near end, its box short of the
    laptop standing at its far end."""
    laptop = node(1, "laptop", (0.0, 0.0), (0.3, 0.25), (0.75, 0.77))
    table_end = node(2, "dining_table", (0.0, -0.75), (0.9, 0.3), (0.0, 0.75))  # 0.48 m short of the laptop
    on = [("laptop", "on", "dining_table")]
    assert ground(laptop, [laptop, table_end], on, ["laptop"], rooms={}, sizes=SIZES).status == "unknown"
    assert could_hold("on", laptop, table_end, SIZES)
    far_table = node(2, "dining_table", (0.0, -3.0), (1.7, 1.0), (0.0, 0.75))  # seen whole, 2.4 m away
    assert ground(laptop, [laptop, far_table], on, ["laptop"], rooms={}, sizes=SIZES).status == "fails"
    # a relation that holds stays held: the rule only keeps a failing one open
    table = node(2, "dining_table", (0.0, 0.0), (1.7, 1.0), (0.0, 0.75))
    assert ground(laptop, [laptop, table], on, ["laptop"], rooms={}, sizes=SIZES).status == "holds"


def test_rooms_are_not_grown():
    assert not could_hold("in", node(1, "bed", (0, 0)), node(2, "bed", (3, 0), (2.0, 0.05)), SIZES)


@pytest.mark.skipif(not SHARED.is_file(), reason="needs ../shared/data/procthor/train.jsonl.gz")
def test_the_command_learns_from_a_houses_file_anywhere_and_round_trips(tmp_path, capsys):
    houses = houses_elsewhere(SHARED, tmp_path, 3, "three.jsonl.gz")
    out = tmp_path / "sizes.json"
    assert cli_main(["size-prior", "--houses", str(houses), "--out", str(out), "--min-count", "1"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    prior = load(out)
    assert prior.source == "three.jsonl.gz" and summary["categories"] == len(prior.sizes) > 0
    assert all(long >= short >= 0 for long, short in prior.sizes.values())


def test_the_command_names_a_houses_file_it_cannot_read(tmp_path, capsys):
    assert cli_main(["size-prior", "--houses", str(tmp_path / "nope.jsonl.gz"), "--out", str(tmp_path / "s.json")]) == 2
    assert "nope.jsonl.gz" in capsys.readouterr().err


def test_a_users_own_size_file_anywhere_is_read_and_a_bad_one_names_the_setting(tmp_path):
    from hiconav.reasoning.config import ReasoningConfig
    from hiconav.reasoning.verifier import OfflineVerifier

    path = tmp_path / "elsewhere" / "my_sizes.json"
    path.parent.mkdir()
    size_prior.save(SizePrior({"bed": (2.0, 1.4)}, {"bed": 9}, "mine"), path)
    config = ReasoningConfig.model_validate({"offline": {"size_prior": str(path)}})
    assert OfflineVerifier(config)._sizes == {"bed": (2.0, 1.4)}
    missing = ReasoningConfig.model_validate({"offline": {"size_prior": str(tmp_path / "nope.json")}})
    with pytest.raises(ValueError, match=r"reasoning\.offline\.size_prior: .*nope\.json"):
        OfflineVerifier(missing)
