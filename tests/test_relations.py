"""Spatial relations on hand-built objects: on, next to, near, under, in a room."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiconav.relations import (
    NEAR,
    NEXT_TO,
    Thing,
    holds,
    in_polygon,
    is_near,
    is_next_to,
    is_on,
    is_under,
    plan_overlap,
    planar_gap,
    polygon_distance,
)


def thing(category="chair", center=(0.0, 0.0), size=(0.5, 0.5), yaw=0.0, z0=0.0, z1=0.8) -> Thing:
    return Thing(category, center, size, yaw, z0, z1)


def test_gap_between_boxes_side_by_side_is_the_space_between_their_faces() -> None:
    assert planar_gap(thing(center=(0, 0)), thing(center=(1.5, 0))) == pytest.approx(1.0)


def test_gap_between_boxes_apart_diagonally_is_corner_to_corner() -> None:
    assert planar_gap(thing(center=(0, 0)), thing(center=(1.5, 1.5))) == pytest.approx(math.hypot(1.0, 1.0))


def test_gap_of_a_rotated_box_is_measured_to_its_corner() -> None:
    # a 1 m square turned by 45 degrees reaches sqrt(0.5) m towards the other box
    diamond = thing(center=(2.0, 0.0), size=(1.0, 1.0), yaw=math.pi / 4)
    assert planar_gap(thing(center=(0, 0)), diamond) == pytest.approx(2.0 - 0.25 - math.sqrt(0.5))


def test_overlapping_boxes_have_no_gap() -> None:
    assert planar_gap(thing(center=(0, 0), size=(2, 2)), thing(center=(0.5, 0.5))) == 0.0


def test_boxes_that_only_touch_do_not_overlap_in_plan() -> None:
    a, b = thing(center=(0, 0)), thing(center=(0.5, 0))
    assert planar_gap(a, b) == pytest.approx(0.0)
    assert not plan_overlap(a, b)
    assert plan_overlap(a, thing(center=(0.3, 0)))


def test_next_to_holds_up_to_one_metre_between_the_boxes() -> None:
    a = thing(center=(0, 0))
    assert is_next_to(a, thing(center=(0.5 + NEXT_TO - 0.05, 0)))
    assert not is_next_to(a, thing(center=(0.5 + NEXT_TO + 0.05, 0)))


def test_near_holds_up_to_two_metres_between_the_boxes() -> None:
    a = thing(center=(0, 0))
    assert is_near(a, thing(center=(0.5 + NEAR - 0.05, 0)))
    assert not is_near(a, thing(center=(0.5 + NEAR + 0.05, 0)))


def test_a_vase_standing_on_a_table_is_on_it() -> None:
    table = thing("dining_table", center=(0, 0), size=(1.6, 0.9), z0=0.0, z1=0.75)
    vase = thing("vase", center=(0.5, 0.2), size=(0.15, 0.15), z0=0.76, z1=1.0)
    assert is_on(vase, table)
    assert not is_on(table, vase)


def test_an_object_beside_a_table_or_above_it_in_the_air_is_not_on_it() -> None:
    table = thing("dining_table", center=(0, 0), size=(1.6, 0.9), z0=0.0, z1=0.75)
    assert not is_on(thing("vase", center=(1.2, 0.0), size=(0.15, 0.15), z0=0.75, z1=1.0), table)
    assert not is_on(thing("vase", center=(0.0, 0.0), size=(0.15, 0.15), z0=1.3, z1=1.5), table)


def test_on_uses_the_lower_box_own_axes() -> None:
    # a long bench turned by 90 degrees: a point 0.9 m north of its centre lies over it
    bench = thing("stool", center=(0, 0), size=(2.0, 0.4), yaw=math.pi / 2, z0=0.0, z1=0.45)
    assert is_on(thing("plant", center=(0.0, 0.9), size=(0.1, 0.1), z0=0.45, z1=0.7), bench)
    assert not is_on(thing("plant", center=(0.9, 0.0), size=(0.1, 0.1), z0=0.45, z1=0.7), bench)


def test_a_sofa_below_a_painting_hung_over_it_is_under_it() -> None:
    sofa = thing("sofa", center=(0, 0), size=(2.0, 0.9), z0=0.0, z1=0.9)
    painting = thing("painting", center=(0.0, 0.3), size=(0.8, 0.03), z0=1.2, z1=1.8)
    assert is_under(sofa, painting)
    assert not is_under(painting, sofa)


def test_an_object_above_but_beside_in_plan_is_not_over_it() -> None:
    sofa = thing("sofa", center=(0, 0), size=(2.0, 0.9), z0=0.0, z1=0.9)
    assert not is_under(sofa, thing("painting", center=(2.0, 0.3), size=(0.8, 0.03), z0=1.2, z1=1.8))


def test_holds_dispatches_by_the_relation_name_and_refuses_unknown_ones() -> None:
    a, b = thing(center=(0, 0)), thing(center=(1.0, 0))
    assert holds("next to", a, b) and holds("near", a, b)
    assert not holds("on", a, b) and not holds("under", a, b)
    with pytest.raises(ValueError, match="left of"):
        holds("left of", a, b)


L_SHAPE = np.array([[0, 0], [4, 0], [4, 2], [2, 2], [2, 4], [0, 4]], dtype=float)


def test_a_point_in_the_arms_of_an_l_shaped_room_is_inside_and_the_notch_is_not() -> None:
    assert in_polygon((1.0, 3.0), L_SHAPE) and in_polygon((3.0, 1.0), L_SHAPE)
    assert not in_polygon((3.0, 3.0), L_SHAPE)


def test_a_point_on_a_shared_wall_belongs_to_one_room_only() -> None:
    west = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    east = np.array([[2, 0], [4, 0], [4, 2], [2, 2]], dtype=float)
    assert in_polygon((2.0, 1.0), west) != in_polygon((2.0, 1.0), east)


def test_distance_to_a_room_is_zero_inside_and_to_the_nearest_wall_outside() -> None:
    assert polygon_distance((1.0, 1.0), L_SHAPE) == 0.0
    assert polygon_distance((3.0, 3.0), L_SHAPE) == pytest.approx(1.0)
    assert polygon_distance((5.0, 1.0), L_SHAPE) == pytest.approx(1.0)
