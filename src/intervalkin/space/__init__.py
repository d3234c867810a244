"""space/: the paper's definition sets, built on certified pavings and solves.

aspect                  components of W of one certified sign of det A
aspect_retraction       certified monotone directions (and OUT by combinations) of boxes of one sign's set
aspect_cover_graph      face pairs, retraction ranks and separations of an aspect cover
aspect_topology         covers of each sign: the number of aspects with lower and upper bounds
singular_surface        the singular layer of the workspace and the image g(S)
joint_space             joint cells off an outer enclosure of g(S) (voxel grid)
joint_paving            joint space paved directly: boxes proved off g(S), adaptive (solve.joint_box)
joint_cells             the cells of that paving, their certified counts, joins, regions from cells
joint_pieces            the two pieces of each fold box (solve.fold_model) and the points that join them to cells
joint_models            the local models of the undecided leaves (exclusion, fold), computed once per leaf
joint_leaves            the leaves of that paving: bisection fronts, their tests, refinement
joint_windows, joint_window_pieces   window models of the leaves left without a fold model; window-clear leaves and folds
joint_places            the open places a joint paving leaves (where a cell could hide or a join be missing)
joint_closure           closed cells: cells proved to be whole components of the joint box minus g(S)
joint_separation        separations: cells of one signature proved to be different components (the graph G_sigma)
joint_patterns          patterns: solutions per super-window of a window model; which two may meet on a face
joint_pattern_nodes     window-modelled leaves as one node of G_sigma per possible pattern
joint_refutation        contacts of G_sigma refuted by window models of both ends, on the shortest chains
joint_retraction        the open layer retracted into the cells: the local step of an upper bound
retraction_nodes, retraction_ranks   the retraction's nodes with their ways out; their ranks (a fixed point)
characteristic_surface  aspect boxes certified off S_c
pieces, sheets, voxel_paths   pieces of certified boxes and the sheet above a cell each lies on
basic_region            basic regions and basic components (Theorem 1, Proposition 1)
uniqueness_domain       uniqueness domains (Theorem 2)
pose_label              the certified labels of one exact pose
pose_path, joint_route  a pose's basic region by a certified path into a labelled box (routes through joint cells)
segment, path_search, trajectory, trajectory_result   certified non-singular trajectories
"""
