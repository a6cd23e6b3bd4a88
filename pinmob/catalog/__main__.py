from .registry import main

raise SystemExit(main())
