"""certify/: the certificate files, written from library results and re-checked before writing.

writer             the folder format and :func:`write_certificates`
evidence           results as exact claim fields; each claim is run through the checker first
solve_claims       ``dkp``, ``joint_cell`` and ``trajectory`` claims
workspace_claims   ``aspect_distinct``, ``region_distinct``, ``box_labels`` and ``counts`` claims
aspect_claims      ``aspect_connected`` claims
joint_claims       ``joint_fold_model`` and ``joint_join`` claims of a direct joint paving with fold pieces
"""
