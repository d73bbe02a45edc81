"""Open SABRE's .xmf and .pvd files with ParaView and check what it reads (pvpython script).

Run by regress/unit/test_paraview through tools/pvpython (ParaView 5.11's own Python under a
virtual display): `tools/pvpython regress/unit/paraview_open.py EXPECT.json`. EXPECT.json
holds, per run, the plot files' times, grid (dims, origin, spacing, bounds), cell count,
field ranges of the last plot file, the .xmf list and the .pvd; for a run with "png" also
the bar's extent. Prints one PASS/FAIL line per check and exits 1 if any fails.
"""
import json
import os
import sys

from paraview.simple import (ColorBy, CreateView, Delete, ExtractSurface, ForceTime,
                             OpenDataFile, Reflect, ResetCamera, SaveScreenshot, Show,
                             Threshold, XDMFReader, Xdmf3ReaderT)
from paraview import servermanager
from vtkmodules.vtkIOImage import vtkPNGReader
from vtkmodules.util.numpy_support import vtk_to_numpy

FAILS = []


def check(ok, what):
    print("%s %s" % ("PASS" if ok else "FAIL", what), flush=True)
    if not ok:
        FAILS.append(what)


def close(a, b, tol):
    return all(abs(x - y) <= tol for x, y in zip(a, b)) and len(a) == len(b)


def at_time(reader, t):
    """The reader's dataset at time t, fetched to this process."""
    forced = ForceTime(Input=reader, ForcedTime=t, IgnorePipelineTime=1)
    data = servermanager.Fetch(forced)
    Delete(forced)
    return data


def check_dataset(tag, data, want):
    size = max(b - a for a, b in zip(want["bounds"][0::2], want["bounds"][1::2]))
    geo_tol = 1e-9 * size
    check(data.IsA("vtkImageData"), "%s: an image (uniform) grid, got %s"
          % (tag, data.GetClassName()))
    if not data.IsA("vtkImageData"):
        return
    check(list(data.GetDimensions()) == want["dims"], "%s: dimensions %s (points), want %s"
          % (tag, list(data.GetDimensions()), want["dims"]))
    check(close(data.GetOrigin(), want["origin"], geo_tol), "%s: origin %s, want %s"
          % (tag, list(data.GetOrigin()), want["origin"]))
    check(close(data.GetSpacing(), want["spacing"], 1e-12 * max(want["spacing"])),
          "%s: spacing %s, want %s" % (tag, list(data.GetSpacing()), want["spacing"]))
    check(close(data.GetBounds(), want["bounds"], geo_tol), "%s: bounds %s, want %s"
          % (tag, list(data.GetBounds()), want["bounds"]))
    if want["ndim"] < 3:
        b = data.GetBounds()
        check(b[5] == b[4], "%s: flat (zero thickness along z): z %g..%g" % (tag, b[4], b[5]))
    check(data.GetNumberOfCells() == want["cells"], "%s: %d cells, want %d"
          % (tag, data.GetNumberOfCells(), want["cells"]))
    cd = data.GetCellData()
    for name, (lo, hi) in sorted(want["ranges"].items()):
        arr = cd.GetArray(name)
        if arr is None:
            check(False, "%s: cell array %s missing (has %s)" % (
                tag, name, [cd.GetArrayName(i) for i in range(cd.GetNumberOfArrays())]))
            continue
        got = arr.GetRange(0)
        tol = 1e-14 * max(abs(lo), abs(hi), 1e-300)
        check(close(got, (lo, hi), tol) and arr.GetNumberOfTuples() == want["cells"],
              "%s: %s range %.17g..%.17g, want %.17g..%.17g" % (tag, name, got[0], got[1],
                                                                lo, hi))


def check_series(tag, reader, want, want_times):
    """The reader's time steps (unless want_times is None) and its data at the last one."""
    print("%s: read by %s" % (tag, reader.GetXMLName()))
    if want_times is not None:
        times = [float(t) for t in reader.TimestepValues]
        tol = 1e-12 * max(abs(t) for t in want_times)
        check(close(times, want_times, tol), "%s: time steps %s, want %s"
              % (tag, times, want_times))
    check_dataset(tag, at_time(reader, want["times"][-1]), want)


def render_bar(reader, want):
    """eps_p inside the bar at the last time, mirrored about the axis, after reset camera."""
    t = want["times"][-1]
    forced = ForceTime(Input=reader, ForcedTime=t, IgnorePipelineTime=1)
    inside = Threshold(Input=forced, Scalars=["CELLS", "phi_bar"], LowerThreshold=0.0,
                       UpperThreshold=0.0, ThresholdMethod="Below Lower Threshold")
    # as polygons first: Reflect turns pixel cells inside out
    whole = Reflect(Input=ExtractSurface(Input=inside), Plane="X Min")
    view = CreateView("RenderView")
    view.ViewSize = [600, 1000]
    view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 0
    view.InteractionMode = "2D"
    disp = Show(whole, view)
    ColorBy(disp, ("CELLS", "eps_p"))
    disp.RescaleTransferFunctionToDataRange(True)
    ResetCamera(view)
    SaveScreenshot(want["png"], view, ImageResolution=[600, 1000])
    print("wrote %s" % want["png"])

    png = vtkPNGReader()
    png.SetFileName(want["png"])
    png.Update()
    img = png.GetOutput()
    w, h, _ = img.GetDimensions()
    rgb = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
    fg = (rgb < 245).any(axis=2)
    rows, cols = fg.any(axis=1).nonzero()[0], fg.any(axis=0).nonzero()[0]
    check(rows.size > 0, "picture: the bar is drawn (%d coloured pixels)" % fg.sum())
    if rows.size == 0:
        return
    ph, pw = rows[-1] - rows[0] + 1, cols[-1] - cols[0] + 1
    inside_frame = rows[0] > 0 and cols[0] > 0 and rows[-1] < h - 1 and cols[-1] < w - 1
    check(inside_frame, "picture: the whole bar is in the frame (rows %d..%d of %d, columns "
          "%d..%d of %d)" % (rows[0], rows[-1], h, cols[0], cols[-1], w))
    fill = max(ph / h, pw / w)
    # ParaView frames the bar at about 60 %; a 1 m thick slab would leave it at about 3 %
    check(fill > 0.4, "picture: the bar fills %.0f %% of the frame (not a sliver)"
          % (100 * fill))
    x0, x1, y0, y1 = want["bar"]
    aspect = (y1 - y0) / (2 * max(abs(x0), abs(x1)))
    check(abs((ph / pw) / aspect - 1) < 0.1, "picture: bar height/width %.3f, the bar's "
          "%.3f" % (ph / pw, aspect))


def main():
    with open(sys.argv[1]) as f:
        cases = json.load(f)
    for name, want in sorted(cases.items()):
        # one .xmf with the reader ParaView picks (one file has no time steps); all of them
        # as a time series with the Xdmf3 reader T
        xmf = OpenDataFile(want["xmf"][-1])
        check_series("%s %s" % (name, want["xmf"][-1].split("/")[-1]), xmf, want, None)
        if want["ndim"] == 3:  # the legacy XDMF reader, which reads only 3D runs' fields
            legacy = XDMFReader(FileNames=want["xmf"][-1:])
            check_series("%s %s legacy" % (name, want["xmf"][-1].split("/")[-1]), legacy,
                         want, None)
            Delete(legacy)
        series = Xdmf3ReaderT(FileName=want["xmf"])
        check_series("%s .xmf series" % name, series, want, want["times"])
        Delete(series)
        pvd = OpenDataFile(want["pvd"])
        check_series("%s .pvd" % name, pvd, want, want["times"])
        if want.get("png"):
            render_bar(xmf, want)
        Delete(pvd)
        Delete(xmf)
    print("%d checks failed" % len(FAILS), flush=True)
    # skip the interpreter's teardown: under Xvfb, ParaView 5.11 ends it with an X error
    # (GLXBadContext) and exit status 1 whatever the checks said
    os._exit(1 if FAILS else 0)


if __name__ == "__main__":
    main()
