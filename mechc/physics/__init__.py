"""How a mechanism moves: the closed-form kinematics of its parts, and the pymunk scene."""
