"""What people at the rig read: the plan preview, the live progress, the campaign report, exports."""
