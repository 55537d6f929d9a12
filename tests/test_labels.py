"""One label-comparison rule for the whole core: ``hiconav.types.label_key``."""

from __future__ import annotations

import pytest

from hiconav.exploration.planner import _exact_label_match
from hiconav.exploration.utility import LabelScorer
from hiconav.memory.subgraphs import _matches
from hiconav.perception.detector import normalise_label
from hiconav.reasoning.grounding import labels_match, room_of, target_relations
from hiconav.types import TaskSpec, label_key


@pytest.mark.parametrize("label", ["floor_lamp", "Floor Lamp", "floor-lamp", "  floor  lamp ", "FLOOR__LAMP"])
def test_spellings_of_one_label_share_a_key(label):
    assert label_key(label) == "floor_lamp"


def test_different_labels_keep_different_keys():
    assert label_key("floor lamp") != label_key("floorlamp")
    assert label_key("tv_stand") != label_key("tv")


def test_the_detector_folds_synonyms_on_top_of_the_key():
    assert normalise_label("Couch") == "sofa" and normalise_label("TV-Monitor") == "tv"
    assert label_key("Couch") == "couch"  # the comparison itself knows no synonyms


def test_every_matcher_reads_labels_alike():
    for a, b in [("Floor-Lamp", "floor lamp"), ("coffee_table", "Coffee  Table")]:
        assert labels_match(a, b)
        assert _exact_label_match(a, b) == 1.0
    assert room_of("Living-Room") == room_of("living room") == "living_room"
    assert target_relations([("Floor-Lamp", "next to", "sofa")], ["floor lamp"]) == [("Floor-Lamp", "next to", "sofa")]
    assert _matches("Floor-Lamp", ("floor lamp",), lambda a, b: 0.0, 1.0)
    scorer = LabelScorer(TaskSpec("find the floor lamp", targets=("floor lamp",), related=("Coffee-Table",)),
                         lambda a, b: 0.0)
    assert scorer("Floor_Lamp") == 1.0 and scorer.is_related("coffee table")
