"""CARLA to Downpour: the mapping of frames, poses, weather and lamps (mapping), and a bridge
that drives a Downpour session from a running CARLA server (bridge)."""
