"""CARLA to Downpour: the mapping of frames, poses, weather and lamps into the contract's terms
(mapping, plain numbers), and the bridge that drives a session from a CARLA server (bridge: its
map's OpenDRIVE as the session's roads, the ego vehicle, the other vehicles as traffic, weather and
lamps, in lockstep with CARLA's synchronous mode)."""
