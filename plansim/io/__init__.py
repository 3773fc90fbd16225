"""The edge: what crosses into and out of plansim as files (scenario TOML, recordings, results), written atomically."""
