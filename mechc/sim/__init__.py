"""Proofs of a design against a spec: logic, kinematic and dynamic levels."""
