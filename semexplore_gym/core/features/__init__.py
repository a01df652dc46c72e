"""Features for learning agents: egocentric map crops and macro-action observations."""
