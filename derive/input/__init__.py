"""Reading what a user writes: TOML topologies and scenes, checked once, with one-line errors."""
