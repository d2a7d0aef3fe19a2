"""The docking scene, in wings; each wing imports only the wings before it (and the layers below
`drake_dock.docking`: core, systems):

1. `scenario`: the scenario's schema, loading, validation and defaults.
2. `geometry`: the APDS's contact patches, its pairs with their families and hand-overs, the
   `DockingScene` built once from a scenario, rotations.
3. `checks`: the two interpenetration checks, independent of the contact code (analytic and
   triangle-mesh).
4. `model`: the plant, the docking Diagram, the simulation, the outcome rules, control and
   thrust, and the run's `InitialState`: the model runs from any initial state it is given.
5. `placement`: the initial state of a scenario (`place`) from its first contact on a straight
   approach (`first_contact`); it checks the approach with `checks` and produces the model's
   `InitialState`.
6. `report`: a run's numbers, the out directory, the figures and the replay.

A wing's package holds no code and re-exports nothing: import a name from the module that
defines it.
"""
