"""The virtual lab: physics of the simulated rig (DESIGN §3) and simulated instruments on one clock."""
