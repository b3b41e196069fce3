"""The campaign file: one self-describing HDF5 file per campaign, written pose by pose."""
