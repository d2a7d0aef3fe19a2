"""Generic mathematics of drake_dock: no docking knowledge and no Drake imports.

- `patches`: parametric curves and surfaces with first and second derivatives.
- `seeking`: the couple of minimal distance between two patches (Sect. 5.1).
"""
