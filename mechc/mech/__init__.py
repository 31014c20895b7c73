"""Mechanisms: geometry of cells and connectors, their kinematic and dynamic models, checks."""
