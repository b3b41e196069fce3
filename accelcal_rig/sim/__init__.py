"""The virtual lab: physics of the simulated rig (docs/procedures.md, "The simulated rig") and simulated instruments on one clock."""
