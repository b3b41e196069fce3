from accelcal_rig.cli import main

raise SystemExit(main())
