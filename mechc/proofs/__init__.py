"""Proofs of a design against its spec at three levels (logic, kinematic, dynamic), for
combinational and sequential designs."""
