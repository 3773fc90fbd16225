"""Reports: text tables, JSON, figures, and atomic output files."""
