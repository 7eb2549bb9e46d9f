"""The build backend of the sprc Python package (PEP 517, in the tree:
pyproject.toml's `backend-path`). The package is pure Python, so a wheel
is a zip of sprc/ with its metadata; this backend makes it with the
standard library alone, so `pip install ./python` needs nothing from a
package index (no setuptools, no wheel), also on a machine offline.
Metadata come from pyproject.toml's [project] table."""

import base64
import hashlib
import io
import re
import tarfile
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _project():
    """name, version, description, requires-python, dependencies of [project]."""
    text = (HERE / "pyproject.toml").read_text()
    table = re.search(r"^\[project\]\s*$(.*?)(?=^\[|\Z)", text, re.M | re.S).group(1)
    meta = dict(re.findall(r'^([\w-]+)\s*=\s*"([^"]*)"\s*$', table, re.M))
    deps = re.search(r"^dependencies\s*=\s*\[(.*?)\]", table, re.M | re.S)
    meta["dependencies"] = re.findall(r'"([^"]+)"', deps.group(1)) if deps else []
    return meta


def _metadata():
    p = _project()
    lines = ["Metadata-Version: 2.1", f"Name: {p['name']}", f"Version: {p['version']}",
             f"Summary: {p.get('description', '')}", "License: MIT"]
    if "requires-python" in p:
        lines.append(f"Requires-Python: {p['requires-python']}")
    lines += [f"Requires-Dist: {d}" for d in p["dependencies"]]
    lines += ["Description-Content-Type: text/markdown", "", (HERE / "README.md").read_text()]
    return "\n".join(lines) + "\n"


def _dist_info():
    p = _project()
    return f"{p['name']}-{p['version']}.dist-info", f"{p['name']}-{p['version']}"


_WHEEL = "Wheel-Version: 1.0\nGenerator: build_sprc\nRoot-Is-Purelib: true\nTag: py3-none-any\n"


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    info, _ = _dist_info()
    target = Path(metadata_directory) / info
    target.mkdir(parents=True, exist_ok=True)
    (target / "METADATA").write_text(_metadata())
    (target / "WHEEL").write_text(_WHEEL)
    return info


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    info, stem = _dist_info()
    name = f"{stem}-py3-none-any.whl"
    files = {str(f.relative_to(HERE)): f.read_bytes() for f in sorted((HERE / "sprc").rglob("*.py"))}
    files[f"{info}/METADATA"] = _metadata().encode()
    files[f"{info}/WHEEL"] = _WHEEL.encode()
    record = []
    with zipfile.ZipFile(Path(wheel_directory) / name, "w", zipfile.ZIP_DEFLATED) as whl:
        for path, data in files.items():
            whl.writestr(path, data)
            digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
            record.append(f"{path},sha256={digest},{len(data)}")
        record.append(f"{info}/RECORD,,")
        whl.writestr(f"{info}/RECORD", "\n".join(record) + "\n")
    return name


def build_sdist(sdist_directory, config_settings=None):
    _, stem = _dist_info()
    name = f"{stem}.tar.gz"
    with tarfile.open(Path(sdist_directory) / name, "w:gz") as tar:
        for f in ["pyproject.toml", "build_sprc.py", "README.md", *sorted(
                str(p.relative_to(HERE)) for p in (HERE / "sprc").rglob("*.py"))]:
            tar.add(HERE / f, arcname=f"{stem}/{f}")
        pkg = f"Metadata-Version: 2.1\nName: {_project()['name']}\nVersion: {_project()['version']}\n".encode()
        entry = tarfile.TarInfo(f"{stem}/PKG-INFO")
        entry.size = len(pkg)
        tar.addfile(entry, io.BytesIO(pkg))
    return name
