"""Task episodes (objectnav, ovon, textnav): generation per seed, the words of ovon instructions,
textnav descriptions that single out their instance, and the per-line checks of the reader."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from sim_synthetic import box_room, obj

from hiconav.errors import DataError
from hiconav.reasoning.decompose import OfflineParser
from hiconav.relations import holds, in_polygon
from hiconav.sim.episodes import generate_episodes
from hiconav.sim.geodesic import centre_free
from hiconav.sim.houses import load_house
from hiconav.sim.task_episodes import (
    OVON_NAMES,
    OVON_PHRASINGS,
    ROOM_NAMES,
    TEXTNAV_PHRASINGS,
    GroundTruth,
    TaskEpisode,
    _article,
    describe_phrase,
    generate_task_episodes,
    parse_line,
    resolve,
    spoken,
    task_seed,
    textnav_candidates,
    thing_of,
)

PARSER = OfflineParser(similarity=None)  # the lexicon alone: no embedding model guesses
# the parser's canonical relation and room names -> ours
RELATION = {"on": "on", "next to": "next to", "near": "near", "under": "under", "below": "under"}
ROOM = {name.replace(" ", "_"): room_type for room_type, name in ROOM_NAMES.items()}


@pytest.mark.parametrize("task", ["objectnav", "ovon", "textnav"])
def test_generation_is_deterministic_per_seed(shared_data, task) -> None:
    house = load_house("procthor:val/5", shared_data)
    a = generate_task_episodes(house, 5, task, 4, seed=1)
    assert a == generate_task_episodes(house, 5, task, 4, seed=1)
    assert a != generate_task_episodes(house, 5, task, 4, seed=2)
    assert [e.episode_id for e in a] == [f"{task}/5/{i}" for i in range(4)]
    assert all(e.task == task and e.house == 5 for e in a)


def test_objectnav_episodes_are_the_generated_objectnav_episodes_with_procthor_ids(shared_data) -> None:
    house = load_house("procthor:val/3", shared_data)
    ours = generate_task_episodes(house, 3, "objectnav", 5, seed=0)
    theirs = generate_episodes(house, 5, seed=task_seed(0, "objectnav", 3))
    for a, b in zip(ours, theirs, strict=True):
        assert a.start == (b.start.x, b.start.y, b.start.yaw) and a.target == b.target
        assert a.instruction == b.instruction
        assert a.goal_object_ids == tuple(house.objects[i].source_id for i in b.goal_instance_ids)


def test_every_procthor_object_has_its_id_and_is_found_by_it(shared_data) -> None:
    house = load_house("procthor:val/3", shared_data)
    ids = [o.source_id for o in house.objects]
    assert all(ids) and len(set(ids)) == len(ids)
    assert all(house.instance_by_source_id(o.source_id) == o.instance_id for o in house.objects)
    assert house.instance_by_source_id("no such id") is None


def _words(category: str) -> str:
    return spoken(category).lower()


@pytest.mark.parametrize("category", sorted(OVON_NAMES))
def test_every_ovon_name_in_every_phrasing_decomposes_to_its_category(category) -> None:
    for name in OVON_NAMES[category]:
        for phrasing in OVON_PHRASINGS:
            text = phrasing.format(a=_article(name), name=name)
            assert PARSER.parse(text).targets[:1] == (category,), text


@pytest.mark.parametrize("category", sorted(OVON_NAMES))
def test_no_ovon_name_says_the_category_in_its_own_words(category) -> None:
    for name in OVON_NAMES[category]:
        assert not re.search(rf"\b{re.escape(_words(category))}\b", name.lower()), (category, name)


def test_generated_ovon_instructions_name_the_target_in_other_words(shared_data) -> None:
    for index in (3, 5, 7):
        house = load_house(f"procthor:val/{index}", shared_data)
        for ep in generate_task_episodes(house, index, "ovon", 4, seed=0):
            assert PARSER.parse(ep.instruction).targets[:1] == (ep.target,), ep.instruction
            assert not re.search(rf"\b{re.escape(_words(ep.target))}\b", ep.instruction.lower()), ep.instruction


def _stated(text: str, target: str) -> list[tuple[str, str]]:
    """The clauses the instruction states about its target, as the parser reads them."""
    task = PARSER.parse(text)
    assert task.targets[:1] == (target,), text
    out = []
    for subject, relation, anchor in task.relations:
        if subject != target:
            continue
        if relation == "in":
            out.append(("in", ROOM[anchor]))
        else:
            out.append((RELATION[relation], anchor))
    return out


def _may_satisfy(house, iid: int, clause: tuple[str, str], rooms: dict[int, str | None]) -> bool:
    """Written here again from the predicates, generously (as a listener might read it)."""
    kind, what = clause
    if kind == "in":
        return rooms[iid] in (None, what)
    obj = house.objects[iid]
    if kind == "on" and obj.parent_id is not None and house.objects[obj.parent_id].category == what:
        return True
    return any(holds(kind, thing_of(obj), thing_of(o)) for o in house.objects
               if o.category == what and o.instance_id != iid)


def _room(house, iid: int) -> str | None:
    xy = house.objects[iid].center[:2]
    return next((r.room_type for r in house.rooms if in_polygon(xy, r.polygon)), None)


def _check_singles_out(house, iid: int, text: str) -> None:
    target = house.objects[iid].category
    clauses = _stated(text, target)
    assert clauses, text
    rooms = {o.instance_id: _room(house, o.instance_id) for o in house.instances_of(target)}
    for clause in clauses:
        assert _may_satisfy(house, iid, clause, rooms), (text, clause)
    for other in house.instances_of(target):
        if other.instance_id != iid:
            assert not all(_may_satisfy(house, other.instance_id, c, rooms) for c in clauses), \
                (house.name, text, other.source_id)


def test_textnav_descriptions_single_out_their_instance_in_24_train_houses(shared_data) -> None:
    rng = np.random.default_rng(0)
    described = 0
    for index in range(24):
        house = load_house(f"procthor:train/{index}", shared_data)
        for iid, clauses in textnav_candidates(house):  # every instance counts as seen (no rendering)
            text = TEXTNAV_PHRASINGS[described % len(TEXTNAV_PHRASINGS)].format(
                np=describe_phrase(house.objects[iid].category, clauses, rng))
            _check_singles_out(house, iid, text)
            described += 1
    assert described >= 24


def test_generated_textnav_episodes_single_out_their_goal(shared_data) -> None:
    for index in (0, 1, 5):
        house = load_house(f"procthor:val/{index}", shared_data)
        for ep in generate_task_episodes(house, index, "textnav", 3, seed=0):
            (goal,) = ep.goal_object_ids
            iid = house.instance_by_source_id(goal)
            assert house.objects[iid].category == ep.target
            assert len(house.instances_of(ep.target)) >= 2
            _check_singles_out(house, iid, ep.instruction)


def test_textnav_prefers_the_room_alone_when_it_is_unique(shared_data) -> None:
    house = load_house("procthor:val/3", shared_data)
    truth = GroundTruth(house)
    chairs = [o.instance_id for o in house.instances_of("chair")]
    alone = [i for i in chairs if sum(truth.room_of(j) == truth.room_of(i) for j in chairs) == 1]
    assert alone, "val/3 has a chair alone in its room"
    for iid in alone:
        assert truth.describe(iid) == [("in", truth.room_of(iid))]


def _twin_chairs(*extra):
    """A living room with a table and a chair on either side of it, alike in every relation."""
    from dataclasses import replace

    objects = [obj(0, "dining_table", (3.0, 3.0, 0.375), (1.6, 0.9, 0.75)),
               obj(1, "chair", (3.0, 2.1, 0.45), (0.5, 0.5, 0.9)),
               obj(2, "chair", (3.0, 3.9, 0.45), (0.5, 0.5, 0.9))]
    objects += [replace(o, instance_id=3 + k) for k, o in enumerate(extra)]
    return box_room(6.0, objects)


def test_an_instance_no_description_singles_out_is_not_described() -> None:
    truth = GroundTruth(_twin_chairs())
    assert truth.describe(1) is None and truth.describe(2) is None


def test_a_landmark_beside_one_twin_describes_it_and_only_it() -> None:
    truth = GroundTruth(_twin_chairs(obj(0, "floor_lamp", (3.9, 1.5, 0.8), (0.4, 0.4, 1.6))))
    assert truth.describe(1) == [("next to", "floor_lamp")]
    assert truth.describe(2) is None


def _two_rooms_split_by_a_wall():
    """A bathroom (x < 3) and a living room (x > 3) sharing the wall x = 3; a painting hangs on
    each side of that wall at its south end, an armchair stands against the living room's side
    0.2 m from it, and one more painting hangs on the bathroom's west wall."""
    from hiconav.sim.house import Room, Wall, assemble_house

    walls = [Wall((0.0, 0.0), (6.0, 0.0), 2.5, 0.1), Wall((6.0, 0.0), (6.0, 4.0), 2.5, 0.1),
             Wall((6.0, 4.0), (0.0, 4.0), 2.5, 0.1), Wall((0.0, 4.0), (0.0, 0.0), 2.5, 0.1),
             Wall((3.0, 0.0), (3.0, 2.8), 2.5, 0.1)]
    rooms = [Room("room|0", "Bathroom", np.array([[0, 0], [3, 0], [3, 4], [0, 4]], float)),
             Room("room|1", "LivingRoom", np.array([[3, 0], [6, 0], [6, 4], [3, 4]], float))]
    objects = [obj(0, "painting", (2.93, 1.0, 1.5), (0.04, 0.8, 0.6)),  # bathroom side of x = 3
               obj(1, "armchair", (3.45, 1.0, 0.45), (0.7, 0.8, 0.9)),  # living room side
               obj(2, "painting", (0.07, 2.0, 1.5), (0.04, 0.8, 0.6))]
    return assemble_house("two rooms", rooms, walls, objects)


def test_a_relation_through_a_wall_describes_nothing_a_person_sees() -> None:
    truth = GroundTruth(_two_rooms_split_by_a_wall())
    assert holds("next to", truth.things[0], truth.things[1])  # 0.13 m apart in plan, through the wall
    assert not truth.same_side(0, 1)
    assert not truth.satisfies(0, ("next to", "armchair"))  # read as a person reads it
    assert truth.may_satisfy(0, ("next to", "armchair"))  # read generously: a reader ignoring walls
    assert ("next to", "armchair") not in truth.candidate_clauses(0)
    assert truth.describe(0) != [("next to", "armchair")]


def test_a_relation_within_one_room_still_describes() -> None:
    from dataclasses import replace

    house = _two_rooms_split_by_a_wall()
    house.objects[1] = replace(house.objects[1], center=np.array([2.45, 1.0, 0.45]))  # now in the bathroom
    truth = GroundTruth(house)
    assert truth.same_side(0, 1)
    assert truth.satisfies(0, ("next to", "armchair"))
    assert truth.describe(0) == [("next to", "armchair")]


def test_on_needs_the_parent_and_the_geometry_for_the_goal() -> None:
    from dataclasses import replace

    house = _twin_chairs(obj(0, "vase", (3.5, 3.0, 0.85), (0.15, 0.15, 0.2)),
                         obj(0, "vase", (1.0, 5.0, 0.1), (0.15, 0.15, 0.2)))
    house.objects[3] = replace(house.objects[3], parent_id=0)  # ProcTHOR puts it on the table
    truth = GroundTruth(house)
    assert truth.satisfies(3, ("on", "dining_table"))
    assert not truth.satisfies(4, ("on", "dining_table"))  # neither parent nor geometry
    house.objects[3] = replace(house.objects[3], center=np.array([3.5, 3.0, 0.3]))  # inside its box
    assert not GroundTruth(house).satisfies(3, ("on", "dining_table"))


def test_a_distractor_whose_parent_is_the_anchor_may_be_on_it_whatever_its_box() -> None:
    from dataclasses import replace

    house = _twin_chairs(obj(0, "vase", (3.5, 3.0, 0.85), (0.15, 0.15, 0.2)),
                         obj(0, "vase", (2.5, 3.0, 0.3), (0.15, 0.15, 0.2)))
    house.objects[3] = replace(house.objects[3], parent_id=0)
    house.objects[4] = replace(house.objects[4], parent_id=0)  # drawn inside the table's box
    truth = GroundTruth(house)
    assert truth.may_satisfy(4, ("on", "dining_table"))
    assert not truth.singles_out(3, [("on", "dining_table")])


def test_textnav_starts_lie_on_the_robot_centre_free_space(shared_data) -> None:
    house = load_house("procthor:val/1", shared_data)
    free = centre_free(house, 0.18)
    for ep in generate_task_episodes(house, 1, "textnav", 4, seed=3):
        rc = house.nav.world_to_cell(np.array(ep.start[:2]))
        assert free[rc[0], rc[1]]
        ids, distance = resolve(ep, house, "f", 1)
        assert 1.5 <= distance <= 30.0 and len(ids) == 1


def test_unknown_task_is_refused_naming_the_known_ones(shared_data) -> None:
    house = load_house("procthor:val/3", shared_data)
    with pytest.raises(DataError, match="objectnav, ovon, textnav"):
        generate_task_episodes(house, 3, "pointnav", 1)


# ------------------------------------------------------------------------------------- lines
GOOD = {"episode_id": "e1", "house": 3, "start": [1.0, 2.0, 0.5], "task": "ovon", "instruction": "find the couch",
        "target": "sofa", "goal_object_ids": ["Sofa|3|0"]}


def _line(**changes) -> str:
    data = {**GOOD, **changes}
    return json.dumps({k: v for k, v in data.items() if v is not ...})


def test_a_good_line_parses_into_its_fields() -> None:
    ep = parse_line(_line(), "eps.jsonl", 4)
    assert ep == TaskEpisode("e1", 3, (1.0, 2.0, 0.5), "ovon", "find the couch", "sofa", ("Sofa|3|0",))
    assert parse_line(json.dumps(ep.to_json()), "eps.jsonl", 1) == ep


@pytest.mark.parametrize(("text", "field", "phrase"), [
    ("{not json", None, "malformed JSON"),
    ("[1, 2]", None, "JSON object"),
    (_line(task="pointnav"), "task", "unknown task"),
    (_line(house=-1), "house", "0-based line"),
    (_line(house="3"), "house", "0-based line"),
    (_line(house=True), "house", "0-based line"),
    (_line(start=[1.0, 2.0]), "start", "[x, y, yaw]"),
    (_line(start=[1.0, "a", 0.0]), "start", "[x, y, yaw]"),
    (_line(goal_object_ids=[]), "goal_object_ids", "non-empty list"),
    (_line(goal_object_ids="Sofa|3|0"), "goal_object_ids", "non-empty list"),
    (_line(task="textnav", goal_object_ids=["a", "b"]), "goal_object_ids", "exactly one"),
    (_line(instruction=""), "instruction", "non-empty string"),
    (_line(target=...), "target", "missing field"),
    (_line(colour="red"), "colour", "unknown field"),
])
def test_a_bad_line_names_the_file_line_and_field(text, field, phrase) -> None:
    with pytest.raises(DataError) as info:
        parse_line(text, "eps.jsonl", 7)
    message = str(info.value)
    assert message.startswith("eps.jsonl:7") and phrase in message
    if field is not None:
        assert f"[{field}]" in message
