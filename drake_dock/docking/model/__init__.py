"""The docking model in Drake: the three-body plant (`plant`), the docking Diagram of a
`DiagramSpec` (`diagram`, with capture watched in `capture`), the simulation of a run from a
given initial state (`simulate`, `initial_state`), the outcome rules (`outcome`), post-contact
thrust (`thrust`) and a controller (`control`). Imports the `scenario` and `geometry` wings."""
