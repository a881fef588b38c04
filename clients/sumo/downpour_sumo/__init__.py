"""Eclipse SUMO feeding a Downpour session: the conversions (convert, no SUMO import) and the
bridge that runs SUMO through TraCI (bridge)."""
