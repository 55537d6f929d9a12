"""Episode sources: house specs from the real ProcTHOR / Gibson files, Habitat episode files,
small picklable specs, bad input recorded instead of aborting."""

from __future__ import annotations

import gzip
import json
import pickle
import shutil

import pytest
from eval_walker import make_specs

from hiconav.errors import DataError
from hiconav.eval.sources import (
    EpisodeSpec,
    derive_seed,
    gibson_house_specs,
    gibson_source,
    habitat_episode_files,
    procthor_house_specs,
)


def test_procthor_data_root_file_maps_to_split_specs(shared_data) -> None:
    specs = procthor_house_specs(shared_data / "procthor" / "val.jsonl.gz")
    assert len(specs) == 100
    assert specs[0] == "procthor:val/0" and specs[-1] == "procthor:val/99"


def test_procthor_file_elsewhere_maps_to_path_specs(shared_data, tmp_path) -> None:
    copy = tmp_path / "my_houses.jsonl.gz"
    shutil.copy(shared_data / "procthor" / "train.jsonl.gz", copy)
    specs = procthor_house_specs(copy)
    assert specs[3] == f"{copy.resolve()}#3" and len(specs) == 100


def test_gibson_maps_give_every_floor(shared_data) -> None:
    specs = gibson_house_specs(shared_data / "gibson" / "train_info.pbz2")
    assert len(specs) == 25
    assert specs[0] == "gibson:Allensville/0"


def test_not_a_pbz2_is_a_data_error_naming_the_file(tmp_path) -> None:
    bad = tmp_path / "maps.pbz2"
    bad.write_bytes(b"not bz2")
    with pytest.raises(DataError, match="maps.pbz2"):
        gibson_house_specs(bad)


def test_habitat_episode_folder_expands_and_unknown_scene_is_recorded(shared_data, tmp_path) -> None:
    folder = tmp_path / "episodes"
    folder.mkdir()
    episodes = {"episodes": [{"episode_id": "0", "scene_id": "data/scene_datasets/gibson/Nowhere.glb",
                              "start_position": [0, 0, 0], "start_rotation": [0, 0, 0, 1],
                              "object_category": "bed", "floor_id": 0}]}
    with gzip.open(folder / "Nowhere_episodes.json.gz", "wt") as fh:
        json.dump(episodes, fh)
    assert habitat_episode_files([folder]) == [folder / "Nowhere_episodes.json.gz"]
    specs = gibson_source(shared_data / "gibson" / "train_info.pbz2", [folder])
    assert len(specs) == 1 and specs[0].error and "Nowhere" in specs[0].error


def test_empty_episode_folder_is_an_error(tmp_path, shared_data) -> None:
    with pytest.raises(DataError, match="no \\*.json.gz"):
        habitat_episode_files([tmp_path])


def test_specs_are_small_and_picklable() -> None:
    spec = make_specs(1)[0]
    blob = pickle.dumps(spec)
    assert len(blob) < 1000
    assert pickle.loads(blob) == spec
    assert EpisodeSpec.from_json(json.loads(json.dumps(spec.to_json()))) == spec


def test_derived_seeds_are_stable_and_distinct() -> None:
    assert derive_seed(0, "procthor:val/3/0") == derive_seed(0, "procthor:val/3/0")
    assert derive_seed(0, "a") != derive_seed(1, "a") != derive_seed(0, "b")
