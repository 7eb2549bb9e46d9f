"""`pip install ./python` into a fresh virtual environment (offline: no
index; the in-tree backend build_sprc.py needs nothing else; pip from
ensurepip, numpy from the interpreter running the tests through a .pth
file), then `python -m sprc SCENE.nml` from outside the source tree; and
the version in pyproject.toml is the package's."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def test_pip_install_and_python_m_sprc(tmp_path):
    env_dir = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(env_dir)], check=True)
    python = env_dir / "bin" / "python"
    site = Path(subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               check=True, capture_output=True, text=True).stdout.strip())
    # numpy of the interpreter running the tests (appended to sys.path: the venv's own packages come first)
    (site / "numpy-of-tests.pth").write_text(str(Path(np.__file__).resolve().parents[1]) + "\n")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["SPRC_LIBRARY"] = os.environ.get("SPRC_LIBRARY", str(ROOT / "build" / "lib" / "libsprc.so"))
    env["PIP_NO_INDEX"] = "1"
    # a copy: nothing is written into the source tree
    source = tmp_path / "python"
    shutil.copytree(ROOT / "python", source, ignore=shutil.ignore_patterns("tests", "__pycache__", "build",
                                                                          "*.egg-info"))
    out = subprocess.run([str(python), "-m", "pip", "install", "--no-index", str(source)], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    where = subprocess.run([str(python), "-c", "import sprc; print(sprc.__file__)"], capture_output=True, text=True,
                           env=env, cwd=tmp_path)
    assert where.returncode == 0, where.stderr
    assert Path(where.stdout.strip()).resolve().is_relative_to(site.resolve())
    run = subprocess.run([str(python), "-m", "sprc", str(ROOT / "example" / "scenes" / "lame_cylinder.nml"),
                          "--levels", "3,4"], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0].split()[:3] == ["level", "dofs", "err_fe"] and len(lines) == 3
    assert [line.split()[0] for line in lines[1:]] == ["3", "4"]
    bad = subprocess.run([str(python), "-m", "sprc", str(tmp_path / "missing.nml")], capture_output=True, text=True,
                         env=env, cwd=tmp_path)
    assert bad.returncode == 2 and "missing.nml" in bad.stderr


def test_pyproject_version_is_the_package_version():
    import re
    import sprc
    text = (ROOT / "python" / "pyproject.toml").read_text()
    assert re.search(r'^version = "([^"]+)"', text, re.M).group(1) == sprc.__version__
