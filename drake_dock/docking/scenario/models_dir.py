"""Where the scenario files shipped with the package are (package data; ./models links here):
a module of its own, so that the command line finds them without importing Drake."""
from pathlib import Path

MODELS_DIR = Path(__file__).resolve().parents[2] / "models"
PAPER_EXAMPLE = MODELS_DIR / "paper_example.yaml"
