"""app/: the ``intervalkin`` command on top of the library; it proves nothing itself.

cli        argument parsing, one handler per sub-command, exit statuses and one-line errors
commands   pave, joint, analyze, paper, trajectory: run the library, write a folder, print a table
label      ``intervalkin label``: one pose looked up in a fresh analysis or a saved workspace.npz
options    options shared by sub-commands (``--geometry``)
progress   stage lines and paving bars on stderr: the progress callback given to the library
output     the output folder: its safety rules, pavings, figures, summary.json, certificates
summary    summary.json and the terminal tables of counts, volumes and cells
export     npz and VTK writers and readers of pavings
report     report.md of ``intervalkin paper``: each claim of the paper beside the certified result
table1     the paper's Table 1 beside the certified solutions
text       the table ``intervalkin dkp`` prints
figures    matplotlib views and slices (imported only when figures are drawn)
animation  the trajectory figures and animation
"""
