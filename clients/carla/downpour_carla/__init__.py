"""CARLA to Downpour: the mapping of frames, poses, weather and lamps into the contract's terms
(mapping). The bridge that drives a session from a CARLA server follows once sessions take road
networks."""
