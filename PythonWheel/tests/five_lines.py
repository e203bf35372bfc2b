import sys, pyvista as pv, spaceskip.pyvista
pl = pv.Plotter(off_screen=True, window_size=(400, 400))
vol = spaceskip.pyvista.add_volume(pl, pv.Wavelet(extent=(-24, 24) * 3), cmap="viridis", opacity="sigmoid")
pl.camera_position = [(90, 60, 75), (0, 0, 0), (0, 0, 1)]
pl.screenshot(sys.argv[1])
