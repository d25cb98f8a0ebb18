"""Jobs: from a validated case to results on disk. Build a case's body, bonds, model and
loads; run it (explicit, static, implicit, modal, study, fatigue, breathing crack); write its
summary, results and figures. The command line is a thin layer over these."""
