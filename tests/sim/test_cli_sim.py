"""`hiconav sim` walks a house and writes a Rerun recording."""

from __future__ import annotations

from hiconav.sim.cli import scripted_walk
from hiconav.sim.houses import load_house
from hiconav.sim.simulator import Simulator


def test_sim_command_writes_a_recording(tmp_path, capsys):
    from hiconav.cli import main

    out = tmp_path / "out.rrd"
    assert main(["sim", "--house", "procthor:val/3", "--steps", "8", "--record", str(out),
                 "--seed", "2"]) == 0
    assert out.is_file() and out.stat().st_size > 10_000
    assert "procthor:val/3" in capsys.readouterr().out


def test_scripted_walk_moves_and_is_deterministic(shared_data):
    house = load_house("gibson:Allensville", shared_data)
    poses = []
    for _ in range(2):
        sim = Simulator(house)
        sim.observe = lambda: None
        poses.append([sim.pose for _s, _a, _f in scripted_walk(sim, 40, seed=3)])
    assert poses[0] == poses[1]
    assert poses[0][0].distance_to(poses[0][-1]) > 0.5
