"""Calibration files in the forms other tools and firmware read: JSON, CSV, a C header."""
