"""The mechanisms: the five built-in single-dyad mechanisms (:mod:`.builtin`) and the
multi-dyad chains (:mod:`.chains`), their closed-form kinematics, crank motions, the
crank's balance, and the shared vector and data helpers (:mod:`.geometry`)."""
