"""Builds and runs a docking scenario; writes the outputs atomically into a directory."""
from __future__ import annotations

import json

from pydrake.geometry import Meshcat, MeshcatParams, MeshcatVisualizer
from pydrake.systems.framework import DiagramBuilder

from drake_dock.docking.plant import add_docking_plant, set_initial_state
from drake_dock.docking.scene import apds_pairs, initial_state, pair_couples
from drake_dock.figures import initial_configuration_figure
from drake_dock.output import atomic_directory


def make_meshcat() -> Meshcat:
    params = MeshcatParams()
    params.host = "localhost"
    params.port = 0  # any free port; nothing is served beyond this machine
    return Meshcat(params)


def build_diagram(scenario, meshcat=None):
    """The Drake Diagram of the scenario: plant, SceneGraph and, when given, Meshcat.
    Returns (diagram, docking_plant)."""
    builder = DiagramBuilder()
    dp = add_docking_plant(builder, scenario)
    if meshcat is not None:
        MeshcatVisualizer.AddToBuilder(builder, dp.scene_graph, meshcat)
    return builder.Build(), dp


def run(scenario, out_dir) -> dict:
    """Sets up the scenario and writes into ``out_dir`` (atomically): ``summary.json``,
    ``initial_configuration.png`` and ``replay.html`` (meshcat, self-contained). The hybrid
    contact simulation is not part of this version: the state is the initial condition."""
    state = initial_state(scenario)
    meshcat = make_meshcat()
    diagram, dp = build_diagram(scenario, meshcat)
    context = diagram.CreateDefaultContext()
    plant_context = dp.plant.GetMyContextFromRoot(context)
    set_initial_state(dp, plant_context, state)
    poses = {}
    for name, frame in dp.apds_frames.items():
        X = frame.CalcPoseInWorld(plant_context)
        poses[name] = (X.rotation().matrix(), X.translation())
    pairs = [p for p in apds_pairs(scenario.geometry) if p.name in state.closing_pairs]
    couples = dict(zip((p.name for p in pairs), pair_couples(pairs, poses)))
    summary = {
        "scenario_initial": {"target_yaw_deg": scenario.initial.target_yaw_deg,
                             "approach_travel_m": scenario.initial.approach_travel,
                             "chaser_speed_mps": scenario.initial.chaser_speed},
        "first_contact_ring_distance_m": state.d_contact,
        "initial_ring_distance_m": state.d0,
        "closing_pairs": state.closing_pairs,
        "closing_gaps_m": {n: c.distance for n, c in couples.items()},
        "simulated": False,
    }
    with atomic_directory(out_dir) as tmp:
        initial_configuration_figure(scenario.geometry, poses, couples,
                                     tmp / "initial_configuration.png")
        meshcat.StartRecording()
        diagram.ForcedPublish(context)
        meshcat.StopRecording()
        meshcat.PublishRecording()
        (tmp / "replay.html").write_text(meshcat.StaticHtml())
        (tmp / "summary.json").write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n")
    return summary


def format_summary(summary) -> str:
    lines = [f"first contact at ring-face distance {summary['first_contact_ring_distance_m']:.6f} m"
             f" (start {summary['initial_ring_distance_m']:.6f} m)",
             "pairs closing first: " + ", ".join(summary["closing_pairs"])]
    return "\n".join(lines)


