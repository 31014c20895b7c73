from mechc.cli.main import main

raise SystemExit(main())
