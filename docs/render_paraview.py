"""Open seam's results in ParaView and render them to PNG (pvbatch, off screen).

    xvfb-run -a pvbatch docs/render_paraview.py examples/electronics/out docs/images/electronics_paraview.png

Reads results.exo (the Exodus II file, through ParaView's Exodus reader) at its last
time step and colours the mesh by temperature (a 2-D mesh seen from +z); prints the time steps, the node count
and the temperature range ParaView sees, so a run can be checked against seam's own
summary. Needs ParaView (Debian: apt-get install paraview xvfb); not part of .ci/run.
"""

import os
import sys

from paraview.simple import (  # noqa: E402  (pvbatch provides the module)
    ColorBy,
    ExodusIIReader,
    GetActiveViewOrCreate,
    GetAnimationScene,
    GetColorTransferFunction,
    GetScalarBar,
    ResetCamera,
    SaveScreenshot,
    Show,
    UpdatePipeline,
    servermanager,
)


def main():
    out_dir, png = sys.argv[1], sys.argv[2]
    reader = ExodusIIReader(FileName=[os.path.join(out_dir, "results.exo")])
    reader.PointVariables = ["temperature"]
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = times[-1]
    UpdatePipeline(time=times[-1], proxy=reader)
    data = servermanager.Fetch(reader)
    nodes = 0
    lo, hi = float("inf"), float("-inf")
    z_lo, z_hi = float("inf"), float("-inf")
    it = data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        piece = it.GetCurrentDataObject()
        arr = piece.GetPointData().GetArray("temperature")
        if arr is not None:
            nodes += piece.GetNumberOfPoints()
            a, b = arr.GetRange()
            lo, hi = min(lo, a), max(hi, b)
            box = piece.GetBounds()
            z_lo, z_hi = min(z_lo, box[4]), max(z_hi, box[5])
        it.GoToNextItem()
    print(f"ParaView read {len(times)} time step(s), last t = {times[-1]}; "
          f"{nodes} points (summed over blocks); temperature {lo:.6f} .. {hi:.6f} K")
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = [1000, 700]
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.Background = [1, 1, 1]
    try:
        view.OrientationAxesVisibility = 0
    except AttributeError:
        pass
    display = Show(reader, view)
    ColorBy(display, ("POINTS", "temperature"))
    lut = GetColorTransferFunction("temperature")
    lut.RescaleTransferFunction(lo, hi)
    display.SetScalarBarVisibility(view, True)
    bar = GetScalarBar(lut, view)
    bar.Title = "temperature (K)"
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    if z_lo == z_hi:
        # 2-D data (z = 0; an axisymmetric section: x the radius, y the axis): from +z.
        view.CameraPosition = [0.0, 0.0, 1.0]
        view.CameraFocalPoint = [0.0, 0.0, 0.0]
        view.CameraViewUp = [0.0, 1.0, 0.0]
    else:
        # From below: the die's underside (where the power enters) and the sink's base.
        view.CameraPosition = [0.05, -0.07, -0.05]
        view.CameraFocalPoint = [0.0, 0.0, 0.004]
        view.CameraViewUp = [0.0, 0.0, 1.0]
    ResetCamera(view)
    SaveScreenshot(png, view, ImageResolution=[1000, 700])
    print(f"wrote {png}")


main()
