"""The paper's semantic expert, one module per concept.

* ``expert``: :class:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy`, the replan
  schedule and its plug-in points.
* ``params``: its parameters (``SemanticExpertParams``: numbers and the user's six switches).
* ``recipes``: what an expert is made of (plan sources, goal rules, parameter values): today's,
  ``semantic-v2``'s, the paper's method alone, the outside-choice experts'.
* ``versions``: the named versions (``semantic-v2``, ``semantic-v3``; ``semantic`` = the newest).
* ``plan``, ``plan_context``, ``plan_sources``, ``narrow_sources``: what a plan is, what a plan
  source reads, and the sources the expert asks in order.
* ``goal_memory``, ``path_following``, ``counters``: what the expert remembers about goals, how
  it drives a path, and what it counts for the benchmark.
* ``driver``: the expert driven by an outside frontier choice (the macro-action envs).

``docs/policies.md`` ("How the default expert works") tells the story with these files.
"""
