"""Independent references: hand-written closures the package no longer ships (issue 21, item 5)."""
