"""Instrument protocol definitions: chamber register maps and turntable line protocols, as data.

Drivers speak them, simulators answer them, rig configs choose and override them; they import nothing
of the rest of the package.
"""
