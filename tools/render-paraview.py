"""A ParaView picture of a faceted part coloured by a recovered stress field.

    xvfb-run -a pvbatch tools/render-paraview.py PART.stl RUN.xdmf OUT.png \
        [--field sigma_sprc] [--body NAME] [--view AZIM,ELEV] [--title TEXT]

The part's own surface (the STL, each triangle split 4^4 times so that the
colour follows the field inside a facet) coloured by the von Mises stress of
FIELD (sigma_fe, sigma_spr, sigma_sprc) resampled from the last step of the
run's XDMF file (the last level of a uniform study, the last step of an
adaptive one), with the grid's elements as a wireframe. Needs ParaView's
pvbatch (Debian: `apt-get install paraview xvfb`); a docs tool, never run by
`make test`. tools/render-part draws the same without ParaView (matplotlib).
"""
import argparse
import sys

from paraview.simple import (Calculator, ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction,
                             GetScalarBar, MergeBlocks, ProgrammableFilter, ResampleWithDataset, SaveScreenshot,
                             Show, STLReader, Text, XDMFReader)


def main():
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    p.add_argument('stl')
    p.add_argument('xdmf')
    p.add_argument('png')
    p.add_argument('--field', default='sigma_sprc', choices=['sigma_fe', 'sigma_spr', 'sigma_sprc'])
    p.add_argument('--view', default='-60,35', help='camera azimuth and elevation in degrees')
    p.add_argument('--title', default='')
    p.add_argument('--size', default='1400,900')
    args = p.parse_args()

    grid = XDMFReader(FileNames=[args.xdmf])
    steps = grid.TimestepValues
    steps = list(steps) if hasattr(steps, '__len__') else [steps]
    if not steps:
        sys.exit(f'render-paraview: no level in {args.xdmf}')
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = steps[-1]
    merged = MergeBlocks(Input=grid)
    f = args.field
    function = (f'sqrt(0.5*(({f}_xx-{f}_yy)^2+({f}_yy-{f}_zz)^2+({f}_zz-{f}_xx)^2)'
                f'+3*({f}_xy^2+{f}_yz^2+{f}_xz^2))')

    part = STLReader(FileNames=[args.stl])
    fine = ProgrammableFilter(Input=part)
    fine.Script = ('from vtkmodules.vtkFiltersModeling import vtkLinearSubdivisionFilter\n'
                   'from vtkmodules.vtkFiltersCore import vtkTriangleFilter\n'
                   't = vtkTriangleFilter(); t.SetInputData(self.GetInput()); t.Update()\n'
                   's = vtkLinearSubdivisionFilter(); s.SetInputData(t.GetOutput())\n'
                   's.SetNumberOfSubdivisions(4); s.Update()\n'
                   'self.GetOutput().ShallowCopy(s.GetOutput())\n')
    fine.OutputDataSetType = 'vtkPolyData'
    # the stress components resampled (the elements' own interpolation), von Mises from them
    surf0 = ResampleWithDataset(SourceDataArrays=merged, DestinationMesh=fine)
    surf0.PassPointArrays = 0
    surf = vm = Calculator(Input=surf0, ResultArrayName='von_mises', AttributeType='Point Data')
    vm.Function = function
    surf.UpdatePipeline(steps[-1])
    lo, hi = surf.PointData['von_mises'].GetRange()
    print(f'render-paraview: von Mises on the surface {lo:.4g} .. {hi:.4g}')

    view = GetActiveViewOrCreate('RenderView')
    view.ViewSize = [int(v) for v in args.size.split(',')]
    view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 1
    shown = Show(surf, view)
    ColorBy(shown, ('POINTS', 'von_mises'))
    lut = GetColorTransferFunction('von_mises')
    lut.ApplyPreset('Jet', True)
    lut.RescaleTransferFunction(0.0, hi)
    shown.SetScalarBarVisibility(view, True)
    bar = GetScalarBar(lut, view)
    bar.Title = f'von Mises ({f})'
    bar.ComponentTitle = ''
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    mesh = Show(merged, view)
    mesh.SetRepresentationType('Wireframe')
    ColorBy(mesh, None)
    mesh.AmbientColor = mesh.DiffuseColor = [0.15, 0.15, 0.15]
    mesh.Opacity = 0.35
    if args.title:
        t = Text(Text=args.title)
        tr = Show(t, view)
        tr.Color = [0.0, 0.0, 0.0]
        tr.FontSize = 14
        tr.WindowLocation = 'Upper Center'

    view.ResetCamera()
    cam = view.GetActiveCamera()
    azim, elev = (float(v) for v in args.view.split(','))
    cam.Azimuth(azim)
    cam.Elevation(elev)
    view.ResetCamera()
    cam.Dolly(1.3)
    SaveScreenshot(args.png, view, ImageResolution=view.ViewSize)
    print(f'render-paraview: wrote {args.png} (step time {steps[-1]}, field {f})')


main()
