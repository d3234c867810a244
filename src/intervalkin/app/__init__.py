"""app/: the ``intervalkin`` command on top of the library; it proves nothing itself.

cli        argument parsing, one handler per sub-command, exit statuses and one-line errors
commands   pave, joint, analyze, paper, trajectory: run the library, write a folder, print a table
label      ``intervalkin label``: one pose looked up in a fresh analysis or a saved workspace.npz
options    options shared by sub-commands (``--geometry``)
progress   stage lines and paving bars on stderr: the progress callback given to the library
output     the output folder: its safety rules, pavings, figures, summary.json, certificates
summary    summary.json and the terminal tables of counts, volumes and cells
export     npz writers and readers of pavings
vtk_export ParaView files through meshio: workspace and joint VTU, region surfaces
boxes      merging and rasterising labelled boxes (for VTU and surfaces)
surfaces   marching cubes on label grids (scikit-image)
report     report.md of ``intervalkin paper``: each claim of the paper beside the certified result
report_figures  the passage of report.md on each octree figure of the paper
report_html     report.html: report.md with rotatable 3-D views (plotly, self-contained)
markdown_html   the small Markdown subset of report.md as HTML
table1     the paper's Table 1 beside the certified solutions
text       the table ``intervalkin dkp`` prints
figures    the figure table and entry points (imported only when figures are drawn)
figures_workspace, figures_joint   the paper's workspace and joint-space figures
scenes     3-D scenes shared by the PNGs and the HTML
plotting, palette, units   matplotlib set-up, one colour per id, axis names and the phi unit
animation  the trajectory figures and animation
sweep_command   ``intervalkin sweep``: a design sweep (intervalkin.sweeps) into a resumable folder, its report
sweep_plots     the sweep's counts and volumes against the swept parameters
"""
