#!/usr/bin/env python3
"""Hostile-but-legal 3MF files of many tiny cubes, for timing the slicer on them.

  python3 scripts/many_parts.py fan LEVELS OUT.3mf
      10^LEVELS inside-out 0.5 mm cubes from a file of about a kilobyte: one cube object,
      then LEVELS objects of ten components each (1 mm apart along x, y, z, then 10 mm ...).
  python3 scripts/many_parts.py items N SIZE PITCH OUT.3mf
      N build items of one inside-out cube of side SIZE mm, PITCH mm apart on a square grid.

Then: /usr/bin/time -f "%e s %U user %M KB" target/release/dropslice OUT.3mf -o /tmp/x.gco
"""
import sys, zipfile
RELS='<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>'
HEAD='<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">'
def cube(id, size, inverted):
    s=f'<object id="{id}" type="model"><mesh><vertices>'
    for i in range(8):
        s+=f'<vertex x="{(i&1)*size}" y="{((i>>1)&1)*size}" z="{((i>>2)&1)*size}"/>'
    s+='</vertices><triangles>'
    for t in [[0,2,1],[1,2,3],[4,5,6],[5,7,6],[0,1,4],[1,5,4],[2,6,3],[3,6,7],[0,4,2],[2,4,6],[1,3,5],[3,7,5]]:
        if inverted: t=[t[0],t[2],t[1]]
        s+=f'<triangle v1="{t[0]}" v2="{t[1]}" v3="{t[2]}"/>'
    return s+'</triangles></mesh></object>'
def tr(x,y,z): return f'1 0 0 0 1 0 0 0 1 {x} {y} {z}'
def write(name, resources, build):
    with zipfile.ZipFile(name,'w',zipfile.ZIP_DEFLATED,compresslevel=9) as z:
        z.writestr('_rels/.rels',RELS)
        z.writestr('3D/3dmodel.model',HEAD+'<resources>'+resources+'</resources><build>'+build+'</build></model>')
kind=sys.argv[1]
if kind=='fan':
    # 10^levels inverted 0.5 mm cubes, 10 per level, pitch 1 mm then 10 mm along x, y, z
    levels=int(sys.argv[2]); out=sys.argv[3]
    res=cube(1,0.5,True)
    for l in range(levels):
        axis=l%3; pitch=10**(l//3)
        comps=''.join(f'<component objectid="{l+1}" transform="{tr(*[(k*pitch if a==axis else 0) for a in range(3)])}"/>' for k in range(10))
        res+=f'<object id="{l+2}" type="model"><components>{comps}</components></object>'
    write(out,res,f'<item objectid="{levels+1}"/>')
elif kind=='items':
    n=int(sys.argv[2]); size=float(sys.argv[3]); pitch=float(sys.argv[4]); out=sys.argv[5]
    side=int(round(n**0.5+0.5))
    items=''.join(f'<item objectid="1" transform="{tr((i%side)*pitch,(i//side)*pitch,0)}"/>' for i in range(n))
    write(out,cube(1,size,True),items)
