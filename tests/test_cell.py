"""Cell files: loading, saving atomically with a backup, errors naming file and key, editing."""

import datetime as dt
import math
import os
import stat
from pathlib import Path

import numpy as np
import pytest

import robotcell.cell.schema as cellmod
from robotcell import InputError, load_robot, pose_from_vendor, save_robot
from robotcell.cell import Cell, Frame, Provenance, Tool, Track, Turntable
from robotcell.io.yamlfile import parse_yaml

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"


def random_pose(rng, scale=2.0):
    v = np.concatenate([rng.uniform(-1, 1, 3) * scale * 1e3, rng.uniform(-180, 180, 3)])
    v[4] = rng.uniform(-89, 89)
    return pose_from_vendor(v, "kuka")


def test_example_loads_in_si_units():
    c = Cell.load(EXAMPLE)
    assert c.robot.name == "kuka_kr16" and c.name == "kr16_track_turntable"
    t = c.track
    assert t.axis == "x" and t.scale == 1.0 and (t.lower, t.upper) == (0.0, 6.0)
    np.testing.assert_allclose(t.T_L_R0[:3, 3], [0, 0, 0.45])
    np.testing.assert_allclose(t.T_L_R0, pose_from_vendor([0, 0, 450, 0.05, -0.03, 0.02], "kuka"))
    assert t.provenance == Provenance("track", "2025-03-14T10:05:00+01:00", 0.11, "3 touches")
    tt = c.turntable
    assert tt.name == "DKP_400_01" and tt.parent == "world"
    assert tt.lower == pytest.approx(-2 * math.pi) and tt.upper == pytest.approx(2 * math.pi)
    torch = c.tools["torch"]
    assert torch.number == 1 and torch.mass == 3.2
    np.testing.assert_allclose(torch.cog, [0.12, 0, 0.04])
    np.testing.assert_allclose(torch.T_F_TCP[:3, 3], [0.3125, -0.0012, 0.095])
    assert c.tools["pointer"].provenance == Provenance("nominal")
    assert c.frames["part"].parent == "turntable" and c.frames["part"].number == 2


def test_save_load_round_trip(tmp_path):
    c = Cell.load(EXAMPLE)
    rng = np.random.default_rng(1)
    c.update_frame("jig", random_pose(rng), Provenance.now("frame", rms_mm=0.05, note="3 points"))
    c.set_tool("gripper", random_pose(rng, 0.3), Provenance("manual"), number=5, mass=1.5,
               cog=[0.01, 0.0, 0.08])
    out = tmp_path / "cell.yaml"
    c.save(out)
    d = Cell.load(out)
    assert d.robot_model == "kuka_kr16" and d.name == c.name
    assert list(d.tools) == list(c.tools) and list(d.frames) == list(c.frames)
    for name, tool in c.tools.items():
        np.testing.assert_allclose(d.tools[name].T_F_TCP, tool.T_F_TCP, atol=1e-12)
        assert d.tools[name].number == tool.number and d.tools[name].mass == tool.mass
        assert d.tools[name].provenance == tool.provenance
    for name, fr in c.frames.items():
        np.testing.assert_allclose(d.frames[name].pose, fr.pose, atol=1e-12)
        assert (d.frames[name].parent, d.frames[name].provenance) == (fr.parent, fr.provenance)
    np.testing.assert_allclose(d.track.T_L_R0, c.track.T_L_R0, atol=1e-12)
    np.testing.assert_allclose(d.turntable.T_parent_B, c.turntable.T_parent_B, atol=1e-12)
    assert (d.track.lower, d.track.upper) == (c.track.lower, c.track.upper)
    text = out.read_text()
    assert text.startswith("# robotcell cell file") and "89.99999" not in text


def test_save_keeps_previous_version_as_numbered_backup(tmp_path):
    c = Cell.load(EXAMPLE)
    out = tmp_path / "cell.yaml"
    assert c.save(out) is None
    # no backup; the empty lock file the save was locked on stays beside it (docs/cell.md)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cell.yaml", "cell.yaml.lock"]
    assert (tmp_path / "cell.yaml.lock").read_bytes() == b""
    first = out.read_text()
    c.set_tool("torch", np.eye(4), Provenance.now("tcp", rms_mm=0.2))
    assert c.save(out) == tmp_path / "cell.yaml.1.bak"
    assert (tmp_path / "cell.yaml.1.bak").read_text() == first
    assert out.read_text() != first
    np.testing.assert_allclose(Cell.load(out).tools["torch"].T_F_TCP, np.eye(4))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cell.yaml", "cell.yaml.1.bak",
                                                          "cell.yaml.lock"]


@pytest.mark.parametrize("mode", [0o664, 0o640, 0o600])
def test_save_keeps_permissions_of_file_and_backups(tmp_path, mode):
    out = tmp_path / "cell.yaml"
    Cell.load(EXAMPLE).save(out)
    os.chmod(out, mode)
    c = Cell.load(out)
    c.set_tool("torch", np.eye(4), Provenance("manual"))
    c.save(out)
    assert stat.S_IMODE(out.stat().st_mode) == mode
    assert stat.S_IMODE((tmp_path / "cell.yaml.1.bak").stat().st_mode) == mode
    (tmp_path / "cell.yaml.lock").unlink()  # made at the first save; made again, as the file is
    c.save(out)
    assert stat.S_IMODE((tmp_path / "cell.yaml.lock").stat().st_mode) == mode  # lockable by all
    c.save(out)  # the next backup keeps it too
    assert stat.S_IMODE((tmp_path / "cell.yaml.2.bak").stat().st_mode) == mode


def test_new_cell_file_gets_umask_permissions(tmp_path):
    old = os.umask(0o022)
    try:
        Cell.load(EXAMPLE).save(tmp_path / "new.yaml")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "new.yaml").stat().st_mode) == 0o644


def test_cell_and_model_files_in_windows_1252_are_read(tmp_path):
    text = Path(EXAMPLE).read_text(encoding="utf-8")
    p = tmp_path / "cell.yaml"
    p.write_bytes(("# Zelle f\u00fcr Schwei\u00dfen, Pr\u00fcfst\u00fcck\n" + text).encode("cp1252"))
    assert Cell.load(p).robot.name == Cell.load(EXAMPLE).robot.name
    bom = tmp_path / "bom.yaml"
    bom.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    assert Cell.load(bom).name == Cell.load(EXAMPLE).name


@pytest.mark.parametrize("where", ["dump", "fsync", "replace"])
def test_failed_save_leaves_old_file_intact(tmp_path, monkeypatch, where):
    c = Cell.load(EXAMPLE)
    out = tmp_path / "cell.yaml"
    c.save(out)
    before = out.read_bytes()
    c.set_tool("torch", np.eye(4), Provenance("manual"))

    def boom(*args, **kwargs):
        raise OSError("simulated crash")

    if where == "dump":
        monkeypatch.setattr(cellmod, "written_yaml", boom)
    elif where == "fsync":
        real_fsync = os.fsync
        calls = []

        def fsync_second(fd):  # let the backup through, fail while writing the new file
            calls.append(fd)
            if len(calls) > 1:
                raise OSError("simulated crash")
            real_fsync(fd)

        monkeypatch.setattr(cellmod.os, "fsync", fsync_second)
    else:
        real_replace = os.replace

        def replace_not_target(src, dst):
            if Path(dst) == out:
                raise OSError("simulated crash")
            real_replace(src, dst)

        monkeypatch.setattr(cellmod.os, "replace", replace_not_target)
    # A failing write is an InputError naming the file and the reason (the CLI prints it).
    with pytest.raises((OSError, InputError), match="simulated crash"):
        c.save(out)
    assert out.read_bytes() == before
    leftovers = [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    assert leftovers == []
    Cell.load(out)  # still a valid cell file


def test_model_file_path_relative_to_cell_file(tmp_path, monkeypatch):
    models = tmp_path / "models"
    cells = tmp_path / "cells"
    models.mkdir()
    cells.mkdir()
    robot = load_robot("kuka_kr16")
    save_robot(robot, models / "my_kr16.yaml")
    (cells / "cell.yaml").write_text(
        "robot: {model: ../models/my_kr16.yaml, frame: {x: 500, y: 0, z: 0, a: 90, b: 0, c: 0}}\n"
        "tools: {t1: {frame: {z: 200}}}\n")
    monkeypatch.chdir(tmp_path)  # resolution must not depend on the working directory
    c = Cell.load(cells / "cell.yaml")
    q = np.radians([10, -80, 70, 20, 30, 40])
    np.testing.assert_allclose(c.robot.fk(q), robot.fk(q), atol=1e-12)
    np.testing.assert_allclose(c.T_world_R, pose_from_vendor([500, 0, 0, 90, 0, 0], "kuka"))
    other = tmp_path / "elsewhere" / "deeper"
    other.mkdir(parents=True)
    c.save(other / "copy.yaml")
    data = parse_yaml((other / "copy.yaml").read_text(), "copy.yaml")
    assert data["robot"]["model"] == os.path.join("..", "..", "models", "my_kr16.yaml")
    d = Cell.load(other / "copy.yaml")
    np.testing.assert_allclose(d.robot.fk(q), robot.fk(q), atol=1e-12)


BASE = {"robot": {"model": "kuka_kr16"}}


@pytest.mark.parametrize("content, match", [
    ("[1, 2]", r"must be a YAML mapping"),
    ("robot: [\n", r"not valid YAML"),
    ("tools: {}\n", r"key 'robot' is missing"),
    ("robot: {model: kuka_kr16}\ncolour: red\n", r"unknown key\(s\) \['colour'\]"),
    ("robot: {model: no_such_robot}\n", r"key 'robot.model' is invalid: unknown robot"),
    ("robot: {model: models/missing.yaml}\n", r"key 'robot.model' names model file .*missing"),
    ("robot: {model: kuka_kr16}\ntrack: {frame: {x: abc}}\n",
     r"key 'track.frame.x' must be a number, got 'abc'"),
    ("robot: {model: kuka_kr16}\ntrack: {frame: {x: 0, q: 1}}\n",
     r"key 'track.frame' has unknown key\(s\) \['q'\]"),
    ("robot: {model: kuka_kr16}\ntrack: {axis: w}\n", r"key 'track.axis' must be x, y or z"),
    ("robot: {model: kuka_kr16}\ntrack: {min: 10, max: 0}\n", r"key 'track.min' \(10\) must be below"),
    ("robot: {model: kuka_kr16}\ntrack: {scale: 0}\n", r"key 'track.scale' must be > 0"),
    ("robot: {model: kuka_kr16, frame: {x: 1}}\ntrack: {}\n",
     r"key 'robot.frame' must be omitted when the cell has a track"),
    ("robot: {model: kuka_kr16}\nturntable: {parent: floor}\n",
     r"key 'turntable.parent' must be world or robot"),
    ("robot: {model: kuka_kr16}\ntools: {torch: {number: 1}}\n",
     r"key 'tools.torch.frame' is missing"),
    ("robot: {model: kuka_kr16}\ntools: {torch: {frame: {}, number: 0}}\n",
     r"key 'tools.torch.number' must be an integer >= 1"),
    ("robot: {model: kuka_kr16}\ntools: {torch: {frame: {}, mass: -1}}\n",
     r"key 'tools.torch.mass' must be > 0 kg"),
    ("robot: {model: kuka_kr16}\ntools: {torch: {frame: {}, cog: [1, 2]}}\n",
     r"key 'tools.torch.cog' must be a list \[x, y, z\]"),
    ("robot: {model: kuka_kr16}\ntools: {2torch: {frame: {}}}\n",
     r"key 'tools.2torch' is not a valid name"),
    ("robot: {model: kuka_kr16}\ntools: {a: {frame: {}, number: 3}, b: {frame: {}, number: 3}}\n",
     r"tools 'a' and 'b' have the same number 3"),
    ("robot: {model: kuka_kr16}\nframes: {part: {frame: {}, parent: turntable}}\n",
     r"key 'frames.part.parent' is turntable, but the cell has no turntable"),
    ("robot: {model: kuka_kr16}\nframes: {robot: {frame: {}}}\n", r"frame name 'robot' is reserved"),
    ("robot: {model: kuka_kr16}\nframes: {f: {frame: {}, provenance: {rms_mm: 1}}}\n",
     r"key 'frames.f.provenance.source' is missing"),
    (("robot: {model: kuka_kr16}\nframes: {f: {frame: {}, provenance: {source: frame, "
     "time: yesterday}}}\n"), r"key 'frames.f.provenance' is invalid: .*ISO 8601"),
    (("robot: {model: kuka_kr16}\nframes: {f: {frame: {}, provenance: {source: frame, "
     "rms_mm: -2}}}\n"), r"key 'frames.f.provenance' is invalid: .*rms_mm"),
])
def test_bad_files_name_file_and_key(tmp_path, content, match):
    p = tmp_path / "bad_cell.yaml"
    p.write_text(content)
    with pytest.raises(InputError, match=match) as exc:
        Cell.load(p)
    assert str(p) in str(exc.value)


def test_missing_file_and_binary_file(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        Cell.load(tmp_path / "nope.yaml")
    p = tmp_path / "binary.yaml"
    p.write_bytes(b"\xff\xfe\x00robot")
    with pytest.raises(InputError, match="not a text file"):
        Cell.load(p)


def test_unquoted_yaml_timestamp_is_kept_as_iso_text(tmp_path):
    p = tmp_path / "cell.yaml"
    p.write_text("robot: {model: kuka_kr16}\n"
                 "tools: {t: {frame: {}, provenance: {source: tcp, time: 2025-03-14T10:05:00Z}}}\n")
    time = Cell.load(p).tools["t"].provenance.time
    assert dt.datetime.fromisoformat(time) == dt.datetime(2025, 3, 14, 10, 5, tzinfo=dt.UTC)


def test_editing_api_keeps_numbers_and_checks():
    c = Cell.load(EXAMPLE)
    T = pose_from_vendor([100, 20, 300, 10, 20, 30], "kuka")
    tool = c.set_tool("torch", T, Provenance("tcp", "2025-04-01T08:00:00+02:00", 0.3))
    assert tool.number == 1 and tool.mass == 3.2 and tool.provenance.rms_mm == 0.3
    fr = c.update_frame("part", T, Provenance("workpiece"))
    assert fr.parent == "turntable" and fr.number == 2
    assert c.update_frame("new_base", T, Provenance("manual")).parent == "world"
    with pytest.raises(InputError, match="frames 'fixture' and 'other' have the same number 1"):
        c.update_frame("other", T, Provenance("manual"), number=1)
    with pytest.raises(InputError, match="tools 'torch' and 'other' have the same number 1"):
        c.set_tool("other", T, Provenance("manual"), number=1)
    with pytest.raises(InputError, match="frame name 'world' is reserved"):
        c.update_frame("world", T, Provenance("manual"))
    with pytest.raises(InputError, match="tool name 'my tool' is invalid"):
        c.set_tool("my tool", T, Provenance("manual"))
    with pytest.raises(InputError, match="not a valid rigid transform"):
        c.set_tool("bad", np.diag([1.0, 1.0, -1.0, 1.0]), Provenance("manual"))
    track = c.update_track(Provenance("track", rms_mm=0.05), scale=1.0002)
    assert track.scale == 1.0002 and track.name == "KL1500" and track.provenance.rms_mm == 0.05
    table = c.update_turntable(Provenance("turntable"), T_parent_B=T)
    np.testing.assert_array_equal(table.T_parent_B, T)
    with pytest.raises(InputError, match="track scale must be a finite number > 0"):
        c.update_track(Provenance("track"), scale=-1.0)


def test_cells_without_track_or_turntable_refuse_updates():
    c = Cell(robot=load_robot("kuka_kr16"), robot_model="kuka_kr16")
    with pytest.raises(InputError, match="no track to update"):
        c.update_track(Provenance("track"), scale=1.0)
    with pytest.raises(InputError, match="no turntable to update"):
        c.update_turntable(Provenance("turntable"), T_parent_B=np.eye(4))
    with pytest.raises(InputError, match="carried by the turntable, but the cell has none"):
        c.update_frame("part", np.eye(4), Provenance("manual"), parent="turntable")


def test_component_validation():
    with pytest.raises(InputError, match="track axis must be 'x', 'y' or 'z'"):
        Track(axis="w")
    with pytest.raises(InputError, match="turntable: lower limit 1 must be below upper limit 0"):
        Turntable(lower=1, upper=0)
    with pytest.raises(InputError, match="tool mass must be a finite number > 0"):
        Tool(np.eye(4), mass=0.0)
    with pytest.raises(InputError, match="frame parent must be"):
        Frame(np.eye(4), parent="the floor")
    with pytest.raises(InputError, match="parent 'floor'; the parent must be world, turntable or "
                       "a robot of the cell: robot"):  # a name: the cell knows its robots
        Cell(robot=load_robot("kuka_kr16"), robot_model="kuka_kr16",
             frames={"fix": Frame(np.eye(4), parent="floor")})
    with pytest.raises(InputError, match="provenance source must be a non-empty string"):
        Provenance("")
    with pytest.raises(InputError, match="single pose of shape"):
        Tool(np.stack([np.eye(4)] * 2))
    with pytest.raises(InputError, match="placed by the track"):
        Cell(robot=load_robot("kuka_kr16"), robot_model="kuka_kr16", track=Track(),
             T_world_R=pose_from_vendor([1, 0, 0, 0, 0, 0], "kuka"))
    stamp = Provenance.now("tcp").time
    assert dt.datetime.fromisoformat(stamp).tzinfo is not None


def test_limits():
    c = Cell.load(EXAMPLE)
    np.testing.assert_array_equal(c.track.within_limits([-0.1, 0.0, 3.0, 6.0, 6.1]),
                                  [False, True, True, True, False])
    np.testing.assert_array_equal(c.turntable.within_limits(np.radians([-361, 0, 360, 361])),
                                  [False, True, True, False])
