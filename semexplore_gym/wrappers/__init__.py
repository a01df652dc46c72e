"""wrappers layer."""
