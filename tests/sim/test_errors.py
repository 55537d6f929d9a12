"""Bad input gives one clear message naming the file and field; the CLI shows no traceback."""

from __future__ import annotations

import gzip
import json

import pytest

from hiconav.errors import DataError
from hiconav.sim.houses import load_house


def _house_json(shared_data):
    return json.loads(gzip.open(shared_data / "procthor" / "val.jsonl.gz", "rt").readline())


def test_malformed_house_json_names_file_and_line(shared_data, tmp_path):
    path = tmp_path / "broken.json"
    path.write_text('{"rooms": [\n  {"id": 1,,}\n]}')
    with pytest.raises(DataError, match=r"broken.json:2.*malformed house JSON"):
        load_house(str(path), shared_data)


def test_missing_field_names_the_field(shared_data, tmp_path):
    data = _house_json(shared_data)
    del data["walls"][2]["polygon"]
    path = tmp_path / "house.json"
    path.write_text(json.dumps(data))
    with pytest.raises(DataError, match=r"house.json \[walls\[2\].polygon\]"):
        load_house(str(path), shared_data)


def test_missing_asset_size_names_asset_and_field(shared_data, tmp_path):
    data = _house_json(shared_data)
    data["objects"][1]["assetId"] = "Sofa_Unknown_99"
    data["objects"][1]["objectType"] = "Sofa"
    path = tmp_path / "house.json"
    path.write_text(json.dumps(data))
    with pytest.raises(DataError, match=r"objects\[1\]\.assetId.*Sofa_Unknown_99.*asset-database"):
        load_house(str(path), shared_data)


def test_unknown_house_lists_valid_names(shared_data):
    with pytest.raises(DataError, match=r"unknown house 'kitchen'.*procthor:val/0\.\.99.*Allensville"):
        load_house("kitchen", shared_data)
    with pytest.raises(DataError, match=r"out of range.*0\.\.99"):
        load_house("procthor:val/100", shared_data)
    with pytest.raises(DataError, match=r"unknown Gibson scene 'Nowhere'.*Woodbine"):
        load_house("gibson:Nowhere", shared_data)


def test_cli_prints_one_message_without_traceback(capsys):
    from hiconav.cli import main

    assert main(["sim", "--house", "procthor:nope/1", "--steps", "1"]) == 2
    err = capsys.readouterr().err
    assert "bad ProcTHOR house name" in err and "Traceback" not in err
