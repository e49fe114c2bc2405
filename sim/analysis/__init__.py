"""Reading results: ``truth.py`` (ground truth at buffer resolution, bad-pixel figures), ``depth_panel.py`` (the depth
display read back from a displayed frame), ``disparity_pictures.py`` (the thesis's disparity figures on a pair).

May import: ``spec``, ``golden``, ``sim.models``, ``sim.testbed``.
"""
