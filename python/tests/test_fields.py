"""The fields of a run as numpy arrays (sprc.run) against the HDF5 file the
driver writes for the same scene and levels: bit for bit, every field of
every body and contact pair (read with the HDF5 C library, h5read.py); and
bad requests as clean errors."""

import math
import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

import sprc
from h5read import File
from test_sprc import driver

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "example" / "scenes"


def variant(tmp_path, scene, **changes):
    text = (SCENES / scene).read_text()
    for key, value in changes.items():
        text, n = re.subn(rf"^(\s*{key}\s*=).*$", rf"\g<1> {value}", text, count=1, flags=re.M)
        assert n == 1, key
    path = tmp_path / scene
    path.write_text(text)
    return path


def driver_h5(scene, levels, tmp_path):
    prefix = tmp_path / "out"
    subprocess.run([str(driver()), "run", str(scene), "--levels", ",".join(map(str, levels)), "--output",
                    str(prefix), "--quiet"], check=True, capture_output=True)
    return Path(f"{prefix}.h5")


def dataset(level, grid, field, is_contact):
    group = f"/level_{level:02d}/{grid}"
    if field in ("nodes", "points"):
        return f"{group}/mesh/x", None
    if field == "cells":
        return f"{group}/mesh/connectivity", None
    return f"{group}/node/{field}", f"{group}/cell/{field}"


def same_bits(a, h):
    """a equals the dataset h bit for bit (h may be a padded 2-D vector: a third zero column)."""
    if h.ndim == 2 and a.ndim == 2 and h.shape[1] == 3 and a.shape[1] == 2:
        if not np.all(h[:, 2] == 0.0):
            return False
        h = np.ascontiguousarray(h[:, :2])
    if a.shape != h.shape or a.dtype != h.dtype:
        return False
    view = np.uint64 if a.dtype == np.float64 else np.uint32
    return bool(np.array_equal(a.view(view), h.view(view)))


def compare(study, h5):
    """Every array of every kept level equals its dataset; returns the values compared."""
    compared = 0
    with File(h5) as f:
        for level in study.levels:
            grids = [(n, a, False) for n, a in level.bodies.items()] + \
                    [(f"contact_{k + 1}", a, True) for k, a in enumerate(level.contacts)]
            for name, arrays, is_contact in grids:
                for field, a in arrays.items():
                    node, cell = dataset(level.level, name, field, is_contact)
                    path = node if node in f or cell is None else cell
                    h = f.read(path, a.dtype)
                    if field == "cells":
                        h = h.astype(np.intc)
                    assert same_bits(a, h), (level.level, name, field)
                    compared += a.size
    return compared


@pytest.mark.parametrize("scene, changes, levels, grids", [
    ("lame_cylinder.nml", {}, [3, 4], 1),
    ("lame_cylinder.nml", {"order": 2}, [3], 1),
    ("lame_sphere.nml", {}, [2], 1),
    ("shrink_fit.nml", {}, [3], 2),
], ids=["2d_q1", "2d_q2", "3d_q1", "contact"])
def test_fields_equal_driver_hdf5(tmp_path, scene, changes, levels, grids):
    path = variant(tmp_path, scene, **changes)
    h5 = driver_h5(path, levels, tmp_path)
    study = sprc.run(path, levels=levels)
    assert [r["level"] for r in study.report] == levels == [lv.level for lv in study.levels]
    assert len(study.levels[0].bodies) == grids
    assert compare(study, h5) > 1000
    # the report is run_scene's, times apart
    rows = sprc.run_scene(path, levels=levels)
    for a, b in zip(rows, study.report):
        assert {k: v for k, v in a.items() if not k.startswith("t_")} == \
               {k: v for k, v in b.items() if not k.startswith("t_")}


def test_documented_shapes_and_dtypes():
    study = sprc.run(SCENES / "shrink_fit.nml", levels=3)
    (level,) = study.levels
    shaft = level.bodies["shaft"]
    n, c = len(shaft["nodes"]), len(shaft["cells"])
    expected = {"nodes": ((n, 2), np.float64), "cells": ((c, 4), np.intc), "displacement": ((n, 2), np.float64),
                "sigma_fe": ((n, 3), np.float64), "sigma_spr": ((n, 3), np.float64),
                "sigma_sprc": ((n, 3), np.float64), "inside": ((n,), np.intc), "zz_error_spr": ((c,), np.float64),
                "zz_error_sprc": ((c,), np.float64), "exact_error_fe": ((c,), np.float64), "cut": ((c,), np.intc),
                "volume_fraction": ((c,), np.float64), "cell_level": ((c,), np.intc)}
    assert set(shaft) == set(expected)
    for name, (shape, dtype) in expected.items():
        assert shaft[name].shape == shape and shaft[name].dtype == dtype, name
    assert shaft["cells"].min() == 0 and shaft["cells"].max() == n - 1
    assert np.all(shaft["cell_level"] == 3)
    m = len(level.contact["points"])
    for name in ("p_fe", "p_spr", "p_sprc", "p_exact", "gap", "ts_fe", "ts_sprc", "weight"):
        assert level.contact[name].shape == (m,) and level.contact[name].dtype == np.float64, name
    assert level.contact["normal"].shape == (m, 2) and set(np.unique(level.contact["state"])) <= {0, 1, 2}
    # the weights sum to the slave surface (a quarter circle of radius 20.002) within the cut-cell quadrature
    assert math.isclose(level.contact["weight"].sum(), math.pi * 20.002 / 2, rel_tol=1e-6)


def test_inside_mask_against_the_geometry():
    """`inside` is 1 exactly where the Lamé quarter annulus (5 <= r <= 20,
    x, y >= 0) holds the node; nodes within 1e-9 of the boundary may go
    either way (the geometry's snapping tolerance is ~1e-13 here)."""
    level = sprc.run(SCENES / "lame_cylinder.nml", levels=4).levels[0]
    x = level.bodies["cylinder"]["nodes"]
    r = np.hypot(x[:, 0], x[:, 1])
    distance = np.minimum.reduce([r - 5.0, 20.0 - r, x[:, 0], x[:, 1]])  # > 0 inside (a lower bound near corners)
    inside = level.bodies["cylinder"]["inside"]
    clear = np.abs(distance) > 1e-9
    assert np.array_equal(inside[clear], (distance[clear] > 0).astype(np.intc))
    assert 0 < np.count_nonzero(inside == 0) < len(inside)


def test_keep_only_asked_levels_and_bad_requests(tmp_path):
    lame = SCENES / "lame_cylinder.nml"
    study = sprc.run(lame, levels=[3, 4], keep=4, threads=1)
    assert [r["level"] for r in study.report] == [3, 4] and [lv.level for lv in study.levels] == [4]
    assert study.level(4) is study.levels[0]
    with pytest.raises(ValueError, match=r"fields of level 3 were not kept \(kept: \[4\]\)"):
        study.level(3)
    with pytest.raises(ValueError, match=r"level 9 was not run \(levels run: \[3, 4\]\)"):
        study.level(9)
    with pytest.raises(KeyError, match="level 4 has no 'nobody' .*cylinder"):
        study.levels[0].bodies["nobody"]
    with pytest.raises(KeyError, match="body 'cylinder' at level 4 has no 'stress'.*sigma_fe"):
        study.levels[0].bodies["cylinder"]["stress"]
    assert study.levels[0].contact is None and study.levels[0].contacts == []
    with pytest.raises(sprc.SprcError, match=r"keep: level 5 is not one of the levels run \(3, 4\)"):
        sprc.run(lame, levels=[3, 4], keep=[5])
    with pytest.raises(sprc.SprcError, match="level 99"):
        sprc.run(lame, levels=[99])
    for bad in ([], "4", [4.5]):
        with pytest.raises(ValueError):
            sprc.run(lame, levels=[3, 4], keep=bad)
    for threads in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match="threads"):
            sprc.run(lame, levels=3, threads=threads)
    # a study without SPR-C has no sigma_sprc: a clean KeyError
    spr = variant(tmp_path, "lame_cylinder.nml", recovery="'spr'")
    body = sprc.run(spr, levels=3).levels[0].bodies["cylinder"]
    assert "sigma_spr" in body and "sigma_sprc" not in body
    with pytest.raises(KeyError, match="sigma_sprc"):
        body["sigma_sprc"]


def test_run_scene_threads_and_int_levels():
    lame = SCENES / "lame_cylinder.nml"
    one = sprc.run_scene(lame, levels=3, threads=1)
    two = sprc.run_scene(lame, levels=[3], threads=2)
    assert [r["level"] for r in one] == [3]
    # same bits for any thread count
    assert {k: v for k, v in one[0].items() if not k.startswith("t_")} == \
           {k: v for k, v in two[0].items() if not k.startswith("t_")}
    for threads in (0, -2, "2"):
        with pytest.raises(ValueError, match="threads"):
            sprc.run_scene(lame, levels=3, threads=threads)


def test_thin_layer_study_null_handle():
    with pytest.raises(sprc.SprcError, match="study handle is NULL"):
        sprc.library.get_study_grids(None, 0)


def test_keep_steps_of_an_adaptive_study():
    """In an adaptive study keep names steps (as the C API's keep does), not
    levels: the kept step's fields come back, and no other step's."""
    scene = ROOT / "test" / "data" / "scenes" / "valid" / "kirsch_adaptive.nml"
    study = sprc.run(scene, keep=[1], threads=1)
    assert len(study.report) >= 2
    assert [lv.report["step"] for lv in study.levels] == [1]
    assert study.levels[0].level == study.report[1]["level"]
    assert study.levels[0].bodies["plate"]["cell_level"].max() == study.report[1]["level"]


def test_step_names_one_adaptive_step():
    """Study.step(k) returns step k (several steps may share a finest level,
    which Study.level cannot tell apart); a uniform study has no steps."""
    import pytest

    scene = ROOT / "test" / "data" / "scenes" / "valid" / "kirsch_adaptive.nml"
    study = sprc.run(scene, keep=[0, 1], threads=1)
    last = len(study.report) - 1
    assert last >= 2
    assert study.step(0).step == 0 and study.step(1).step == 1
    assert study.step(1).report == study.report[1]
    with pytest.raises(ValueError, match="not kept"):
        study.step(last)
    with pytest.raises(ValueError, match="not run"):
        study.step(last + 1)
    uniform = sprc.run(ROOT / "example" / "scenes" / "lame_cylinder.nml", levels=[3], threads=1)
    with pytest.raises(ValueError, match="no steps"):
        uniform.step(0)
