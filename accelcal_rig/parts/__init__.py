"""Sensor parts: each part's datasheet facts in one table, looked up by the name a rig config's `part:` gives."""
