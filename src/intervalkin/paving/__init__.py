"""paving/: octree pavings of a box, tri-state labels, face adjacency, memory budget, predicates.

tree        boxes as integer coordinates; level-by-level subdivision of the undecided ones
labels      OUTSIDE / INSIDE / BOUNDARY as bit flags, and how sound labels combine
adjacency   face adjacency (phi seam included) and connected components, in bulk
budget      the depth range and the memory estimate checked before any work
predicates  W (joint limits), the sign of det A and the aspects as labels over arrays of boxes
contract    forward-backward (HC4) contractors for the joint limits and the sign of det A
contracted  undecided leaves cut by the contractors into parts proved INSIDE / OUTSIDE, beside the grid
"""
