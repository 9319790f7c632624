"""python -m evclust.report: write docs/RESULTS.md (see evclust.report.results)."""

from evclust.report.results import main

raise SystemExit(main())
