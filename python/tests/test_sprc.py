"""Tests of the sprc Python package against the library and the driver."""

import csv
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sprc
from sprc import library

ROOT = Path(__file__).resolve().parents[2]
LAME = ROOT / "example" / "scenes" / "lame_cylinder.nml"
BAD = ROOT / "test" / "data" / "scenes" / "bad"
COLUMNS = ("level,h,elements,cut_elements,dofs,t_mesh,t_quadrature,t_assembly,t_solve,t_recovery,t_estimate,"
           "t_total,err_fe,err_spr,err_sprc,eta_spr,eta_sprc,theta_spr,theta_sprc,solver_iterations").split(",")


def driver():
    """The driver built with the library (make lib records it), or $SPRC_DRIVER."""
    path = os.environ.get("SPRC_DRIVER")
    if not path:
        record = ROOT / "build" / "lib" / "driver-path"
        assert record.is_file(), "run `make lib` first (it records the driver next to libsprc.so)"
        path = record.read_text().strip()
    path = Path(path) if Path(path).is_absolute() else ROOT / path
    assert path.is_file(), f"driver {path} not found"
    return path


def scene_variant(tmp_path, **changes):
    """The Lamé example with some &scene fields replaced (levels, recovery)."""
    text = LAME.read_text()
    for key, value in changes.items():
        text, n = re.subn(rf"^(\s*{key}\s*=).*$", rf"\g<1> {value}", text, count=1, flags=re.M)
        assert n == 1, key
    path = tmp_path / "variant.nml"
    path.write_text(text)
    return path


def test_version_matches_fpm_toml_header_and_library():
    toml = (ROOT / "fpm.toml").read_text()
    assert sprc.__version__ == re.search(r'^version\s*=\s*"([^"]+)"', toml, re.M).group(1)
    assert sprc.get_version() == tuple(int(p) for p in sprc.__version__.split("."))
    header = (ROOT / "include" / "sprc.h").read_text()
    parts = [int(re.search(rf"#define SPRC_VERSION_{p} (\d+)", header).group(1)) for p in ("MAJOR", "MINOR", "PATCH")]
    assert tuple(parts) == sprc.get_version()


def test_run_scene_matches_driver_csv(tmp_path):
    """Every cell of the driver's CSV, parsed, equals what run_scene returns:
    exactly (same library code, 17 significant digits round-trip) except the
    wall-clock times, which differ between runs and are checked for presence
    and sign only."""
    prefix = tmp_path / "lame"
    subprocess.run([str(driver()), "run", str(LAME), "--levels", "3,4", "--output", str(prefix), "--quiet"],
                   check=True, capture_output=True)
    with open(f"{prefix}.csv", newline="") as f:
        table = list(csv.reader(f))
    assert table[0] == COLUMNS
    rows = sprc.run_scene(LAME, levels=[3, 4])
    assert len(rows) == len(table) - 1 == 2
    for row, cells in zip(rows, table[1:]):
        assert list(row) == COLUMNS
        for name, cell in zip(COLUMNS, cells):
            value = row[name]
            if cell == "":
                assert value is None, name
            elif name in sprc.INTEGER_COLUMNS:
                assert type(value) is int and value == int(cell), name
            elif name.startswith("t_"):
                assert type(value) is float and math.isfinite(value) and value >= 0.0, name
            else:
                assert type(value) is float and value == float(cell), (name, value, cell)
    assert [r["level"] for r in rows] == [3, 4]
    assert all(0.0 < r["err_fe"] < 1.0 for r in rows)


def test_run_adaptive_scene_matches_driver_csv(tmp_path):
    """An adaptive scene (&adapt): one dict per step with the step and t_adapt
    columns, every cell but the times equal to the driver's CSV (the same
    meshes step by step), the last step within the target."""
    scene = ROOT / "test" / "data" / "scenes" / "valid" / "kirsch_adaptive.nml"
    prefix = tmp_path / "adaptive"
    subprocess.run([str(driver()), "run", str(scene), "--output", str(prefix), "--quiet"], check=True,
                   capture_output=True)
    with open(f"{prefix}.csv", newline="") as f:
        table = list(csv.reader(f))
    assert table[0] == COLUMNS + ["step", "t_adapt"]
    rows = sprc.run_scene(scene)
    assert len(rows) == len(table) - 1 >= 2
    assert [r["step"] for r in rows] == list(range(len(rows)))
    for row, cells in zip(rows, table[1:]):
        for name, cell in zip(table[0], cells):
            if not name.startswith("t_"):
                assert row[name] == (int(cell) if name in sprc.INTEGER_COLUMNS else float(cell)), name
    assert rows[-1]["eta_sprc"] <= 0.03 < rows[0]["eta_sprc"]
    assert rows[-1]["err_fe"] < rows[0]["err_fe"]
    assert all(0.0 <= r["t_adapt"] <= r["t_total"] for r in rows)
    with pytest.raises(sprc.SprcError, match="start level"):
        sprc.run_scene(scene, levels=[3, 4])


def test_scene_levels_by_default(tmp_path):
    rows = sprc.run_scene(scene_variant(tmp_path, levels="2, 3"))
    assert [r["level"] for r in rows] == [2, 3]
    assert rows[0]["dofs"] < rows[1]["dofs"]


def test_empty_cells_are_none(tmp_path):
    (row,) = sprc.run_scene(scene_variant(tmp_path, recovery="'none'"), levels=[3])
    for name in ("t_recovery", "t_estimate", "err_spr", "err_sprc", "eta_spr", "eta_sprc", "theta_spr",
                 "theta_sprc"):
        assert row[name] is None, name
    assert 0.0 < row["err_fe"] < 1.0


def test_run_scene_writes_no_files(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    sprc.run_scene(LAME, levels=[3])
    assert list(tmp_path.iterdir()) == []


def test_missing_file_raises_with_message(tmp_path):
    missing = tmp_path / "no_such_scene.nml"
    with pytest.raises(sprc.SprcError, match="no_such_scene.nml") as info:
        sprc.run_scene(missing)
    assert info.value.status == 5 and info.value.status_name == "i/o error"


def expectations():
    for line in (BAD / "EXPECT").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, *parts = line.split("|")
            stat = next((p[5:] for p in parts if p.startswith("stat=")), "invalid_input")
            yield pytest.param(name, [p for p in parts if not p.startswith("stat=")], stat, id=name)


STATUS = {"invalid_input": 1, "io": 5, "unsupported": 7}


@pytest.mark.parametrize("name, substrings, stat", list(expectations()))
def test_malformed_scene_raises_with_message(name, substrings, stat):
    with pytest.raises(sprc.SprcError) as info:
        sprc.run_scene(BAD / name, levels=[3])
    for text in substrings:
        assert text in str(info.value), (text, str(info.value))
    assert info.value.status == STATUS[stat]


def test_unrunnable_scene_is_unsupported():
    with pytest.raises(sprc.SprcError, match="recovered") as info:
        sprc.run_scene(ROOT / "test" / "data" / "scenes" / "valid" / "hertz_roller.nml")
    assert info.value.status_name == "unsupported"


def test_bad_levels():
    with pytest.raises(sprc.SprcError, match="level 99"):
        sprc.run_scene(LAME, levels=[3, 99])
    for levels in ([], [[3, 4]], [3.5], "3"):
        with pytest.raises(ValueError):
            sprc.run_scene(LAME, levels=levels)


def test_thin_layer_reports_null_handles():
    with pytest.raises(sprc.SprcError, match="report handle is NULL"):
        library.get_report_rows(None)
    with pytest.raises(sprc.SprcError, match="report handle is NULL"):
        library.get_report_values(None, "level", 1)


def test_thin_layer_report_columns():
    report = library.ctypes.c_void_p(library.run_scene(os.fsencode(LAME), None, 0))
    try:
        assert [library.get_report_column(report, j) for j in range(library.get_report_columns(report))] == COLUMNS
        levels = library.get_report_values(report, "level", library.get_report_rows(report))
        np.testing.assert_array_equal(levels, [3, 4, 5, 6])
        with pytest.raises(sprc.SprcError, match="n = 3 but the report has 4 rows"):
            library.get_report_values(report, "level", 3)
        with pytest.raises(sprc.SprcError, match='no report column is named "nope"'):
            library.get_report_value(report, 0, b"nope")
    finally:
        library.delete_report(library.ctypes.byref(report))
    assert not report


def test_library_not_found_names_what_was_tried(tmp_path):
    env = dict(os.environ, SPRC_LIBRARY=str(tmp_path / "libnothing.so"), PYTHONPATH=str(ROOT / "python"))
    out = subprocess.run([sys.executable, "-c", "import sprc"], env=env, capture_output=True, text=True)
    assert out.returncode != 0
    assert "libsprc.so not found" in out.stderr and "libnothing.so" in out.stderr


def test_path_with_nul_is_refused(tmp_path):
    # C would read the path up to the NUL and run another file, silently.
    with pytest.raises(ValueError, match="NUL"):
        sprc.run_scene(str(LAME) + "\0.ignored", levels=[3])
