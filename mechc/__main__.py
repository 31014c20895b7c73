from mechc.cli import main

raise SystemExit(main())
