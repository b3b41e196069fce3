"""The campaign engine: an explicit state machine driven by one injectable clock."""
