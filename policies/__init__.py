"""Policies: scripted expert, frontier baselines and learned agents. They see observations only."""
