"""The docking scene: APDS geometry, the three-body plant and the paper's scenarios."""
