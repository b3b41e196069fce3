"""Instrument interfaces and datasheet facts shared by drivers and simulators."""
