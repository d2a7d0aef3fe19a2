"""The initial placement: a scenario's initial state (`place.place`, with the caller's
`place.PlacementCache`) from the first contact of its straight approach
(`search.Approach`, `search.first_contact`), with the consistent aim for a lateral velocity
(`aim`) and the approach's path checked (`path_check`). Imports the `scenario`, `geometry`,
`checks` and `model` wings (the model's `InitialState`, which it produces); no Drake."""
