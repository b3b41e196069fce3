"""Pose schedules, turntable kinematics and the compiled campaign plan."""
