from accelcal_rig.cli import run_program

run_program()
