"""What an arm DOES: forward kinematics, Jacobians, inverse kinematics."""
