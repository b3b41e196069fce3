from accelcal_rig.cli import run_program

if __name__ == "__main__":  # not when a worker process imports it again
    run_program()
