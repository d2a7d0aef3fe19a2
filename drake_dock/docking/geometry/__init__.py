"""The APDS's geometry: its contact patches (`apds`), the contact pairs with their families and
hand-overs (`pairs`), the scene built once from a scenario (`scene`), its display mesh
(`display_mesh`), rotations and the reach sweep behind the side pairs (`reach`). Imports the
`scenario` wing only; no Drake."""
