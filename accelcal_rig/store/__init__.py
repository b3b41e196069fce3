"""The campaign store: an append-only journal per campaign is the durable truth; the HDF5 file is rebuilt from it."""
