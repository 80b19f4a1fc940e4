"""The learner: torch networks, samples of sets, and one loss term per condition."""
