"""Two-level logic: cubes, truth tables, prime implicants, exact covers."""
