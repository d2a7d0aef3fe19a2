"""Packaging: the scenarios ship inside the package, `--version`, `python -m drake_dock`."""
import importlib.metadata
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import yaml

import drake_dock
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE

ROOT = Path(__file__).resolve().parent.parent


def test_version_is_the_installed_distribution_version(tmp_path):
    out = subprocess.run([sys.executable, "-m", "drake_dock", "--version"], cwd=tmp_path,
                         capture_output=True, text=True, check=True)
    assert out.stdout.strip() == f"drake-dock {importlib.metadata.version('drake_dock')}"


def test_default_scenario_is_package_data_found_from_any_directory(tmp_path):
    package = Path(drake_dock.__file__).resolve().parent
    assert PAPER_EXAMPLE.is_file() and package in PAPER_EXAMPLE.resolve().parents
    code = ("from drake_dock.docking.scenario.loading import load_scenario; "
            "print(load_scenario().initial)")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True)
    assert str(load_scenario(ROOT / "models" / "paper_example.yaml").initial) in out.stdout


def test_wheel_ships_the_models(tmp_path):
    # Built from a copy: setuptools writes build/ next to pyproject.toml.
    src = tmp_path / "src"
    shutil.copytree(ROOT / "drake_dock", src / "drake_dock",
                    ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, src / name)
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path),
                    str(src)], check=True, capture_output=True)
    (wheel,) = tmp_path.glob("drake_dock-*.whl")
    with zipfile.ZipFile(wheel) as z:
        for f in (ROOT / "models").glob("*.yaml"):
            shipped = yaml.safe_load(z.read(f"drake_dock/models/{f.name}"))
            assert shipped == yaml.safe_load(f.read_text())
        assert "drake_dock/__main__.py" in z.namelist()
