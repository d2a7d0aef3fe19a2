"""drake_dock: capture-phase docking contact between two APDS-equipped spacecraft, after Zhao,
Liu and Chen (2016), on Drake.

Layers, each importing only the ones below it:
- `drake_dock.core`: the paper's mathematics (patches, seeking, couples, constraints, the hybrid
  rules of a pair, LZB in `core.lzb`); numpy and scipy only.
- `drake_dock.systems`: the Drake boundary (the contact LeafSystem, the simulator, witness step
  control).
- `drake_dock.docking`: the docking scene, in wings (scenario, geometry, checks, model,
  placement, report: its docstring gives their order).
- `drake_dock.studies`: small scenes, the compliant baseline and the studies (`drake-dock
  study`).
- `drake_dock.campaign`: seeded campaigns on Dask.
- `drake_dock.run` and `drake_dock.cli` on top.
"""
__version__ = "0.1.0"
