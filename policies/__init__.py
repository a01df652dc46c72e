"""Policies: scripted expert, frontier baselines and learned agents. They see observations only."""

if __name__ == "policies":  # imported by the pre-0.2 path from a source checkout
    raise ImportError(
        "the policies are imported as 'semexplore_gym.policies' since version 0.2 "
        "(e.g. 'from semexplore_gym.policies.registry import make_policy'), not as 'policies'"
    )
