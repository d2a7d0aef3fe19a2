"""The two interpenetration checks of two APDS, independent of the contact code: the analytic one
(`penetration`, with `cone_reach`) and the triangle-mesh one (`mesh_check`). Import the
`geometry` wing only (its rotations); no Drake."""
