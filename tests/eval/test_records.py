"""episodes.jsonl: round trip, flushed appends, truncated last line (killed run), bad lines."""

from __future__ import annotations

import math

import pytest

from hiconav.errors import DataError
from hiconav.eval.records import EpisodeRecord, RecordWriter, canonicalise, done_keys, read_records


def rec(episode_id: str, preset: str = "full", **kw) -> EpisodeRecord:
    return EpisodeRecord(episode_id=episode_id, house="procthor:val/0", target="bed", preset=preset, **kw)


def test_round_trip_keeps_every_field_and_unknown_dts(tmp_path) -> None:
    path = tmp_path / "episodes.jsonl"
    original = rec("a", success=True, spl=0.5, dts=math.inf, layer_time_s={"fast": 0.1},
                   layer_frames={"fast": 3}, extra={"note": "x"})
    with RecordWriter(path) as writer:
        writer.write(original)
    (loaded,) = read_records(path)
    assert loaded == original


def test_each_record_is_flushed_as_soon_as_written(tmp_path) -> None:
    path = tmp_path / "episodes.jsonl"
    writer = RecordWriter(path)
    writer.write(rec("a"))
    assert done_keys(path) == {("full", "a")}  # readable before close
    writer.close()


def test_truncated_last_line_is_skipped_and_cut_before_appending(tmp_path) -> None:
    path = tmp_path / "episodes.jsonl"
    with RecordWriter(path) as writer:
        writer.write(rec("a"))
    with path.open("a") as fh:
        fh.write('{"episode_id": "b", "hou')  # a run killed mid-write
    assert done_keys(path) == {("full", "a")}
    with RecordWriter(path) as writer:
        writer.write(rec("c"))
    assert [r.episode_id for r in read_records(path)] == ["a", "c"]


def test_bad_line_in_the_middle_names_file_and_line(tmp_path) -> None:
    path = tmp_path / "episodes.jsonl"
    path.write_text('{"episode_id": "a", "house": "h", "target": "bed"}\nnot json\n'
                    '{"episode_id": "b", "house": "h", "target": "bed"}\n')
    with pytest.raises(DataError, match=r"episodes.jsonl:2"):
        read_records(path)


def test_canonicalise_orders_by_task_order_and_drops_duplicates(tmp_path) -> None:
    path = tmp_path / "episodes.jsonl"
    with RecordWriter(path) as writer:
        for r in (rec("b"), rec("a", preset="no_vis"), rec("a"), rec("b", steps=99)):
            writer.write(r)
    ordered = canonicalise(path, [("full", "a"), ("full", "b"), ("no_vis", "a")])
    assert [r.key for r in ordered] == [("full", "a"), ("full", "b"), ("no_vis", "a")]
    assert read_records(path)[1].steps == 0  # the first record of a duplicated key is kept


def test_record_from_simulator_metrics(tmp_path) -> None:
    sim_metrics = pytest.importorskip("hiconav.sim.metrics")
    episodes = pytest.importorskip("hiconav.sim.episodes")
    from hiconav.types import Pose2D

    episode = episodes.Episode("e1", "procthor:val/0", Pose2D(0, 0, 0), "bed", (3,), 4.0, "find the bed")
    metrics = sim_metrics.episode_metrics(episode, final_distance=0.5, path_length=8.0, steps=40, stopped=True,
                                           shortest_to_success=4.0)
    record = EpisodeRecord.from_metrics(metrics, termination="stop", max_steps=500, vlm_calls=2, detector="oracle")
    assert record.success and record.spl == pytest.approx(0.5) and record.dts == 0.0
    assert (record.geodesic_distance, record.steps, record.vlm_calls) == (4.0, 40, 2)
