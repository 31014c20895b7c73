"""The geometry kernel: circle meetings (the dyad), transforms and bounds, in mm."""
