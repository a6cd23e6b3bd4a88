from pinmob.cli import main

raise SystemExit(main())
