"""Model stage: joint mechanics (tendon stroke -> joint angle), fitting, effects, diagnosis.

Owns: the measurement :class:`~camtube.model.dataset.Dataset`, the base
model plus composable :class:`~camtube.model.api.Effect` terms, bounded
least-squares fits, and the diagnosis of missing physics.
"""
