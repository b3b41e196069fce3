"""`rig serve`: a local web dashboard of running and recent campaigns and of the registry, server-rendered,
every asset bundled (it works with no network)."""
