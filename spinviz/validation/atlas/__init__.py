"""The evidence the regime atlas rests on, beside the project's other checks against the paper
(``spinviz atlas evidence KIND``; ``evidence`` says which module computes each kind)."""
