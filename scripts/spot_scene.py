"""Writes scenes/spot.obj and spot.mtl: the adaptive-elements benchmark scene (scenes/README.md)."""
import os
SCENES=os.path.join(os.path.dirname(os.path.abspath(__file__)),'..','scenes')
V=[];F=[]
def quad(pts,mat,name):
    base=len(V)+1
    V.extend(pts)
    F.append((name,mat,[base,base+1,base+2,base+3]))
def box(lo,hi,mat,name,inward=False):
    x0,y0,z0=lo;x1,y1,z1=hi
    # outward CCW faces
    faces=[
     ([(x0,y0,z0),(x1,y0,z0),(x1,y0,z1),(x0,y0,z1)],'bottom'), # normal -y
     ([(x0,y1,z0),(x0,y1,z1),(x1,y1,z1),(x1,y1,z0)],'top'),    # +y
     ([(x0,y0,z0),(x0,y0,z1),(x0,y1,z1),(x0,y1,z0)],'x0'),     # -x
     ([(x1,y0,z0),(x1,y1,z0),(x1,y1,z1),(x1,y0,z1)],'x1'),     # +x
     ([(x0,y0,z0),(x0,y1,z0),(x1,y1,z0),(x1,y0,z0)],'z0'),     # -z
     ([(x0,y0,z1),(x1,y0,z1),(x1,y1,z1),(x0,y1,z1)],'z1'),     # +z
    ]
    for pts,f in faces:
        if inward: pts=pts[::-1]
        yield pts,f
# check outward normals
def cross(a,b): return [a[1]*b[2]-a[2]*b[1],a[2]*b[0]-a[0]*b[2],a[0]*b[1]-a[1]*b[0]]
def nrm(p):
    n=[0,0,0]
    for k in range(len(p)):
        c=cross(p[k],p[(k+1)%len(p)]); n=[n[i]+c[i] for i in range(3)]
    return n
for pts,f in box((0,0,0),(1,1,1),'m','t'):
    c=[sum(p[i] for p in pts)/4 for i in range(3)]; n=nrm(pts)
    assert sum(n[i]*(c[i]-0.5) for i in range(3))>0,(f,n)
out=["# spot — a small room lit by one small bright ceiling light above a table: sharp shadows",
"# (the adaptive-elements benchmark, README \"Adaptive elements\"). A closed room 4 x 3 x 4 m,",
"# x in [0, 4], y in [0, 3] (up), z in [-4, 0]; a 0.2 x 0.2 m light flush in the ceiling above",
"# a 1.2 x 1.2 m table top 0.8 m high on a 0.1 m square pedestal, and a 0.5 m cube on the floor",
"# (closed boxes, 1 mm clear of the floor and the table, so every ray meets a front face).",
"# The light's penumbra under the table's edge is about 7 cm wide on the floor. Every face is",
"# counter-clockwise seen from its front (the room's inside, the objects' outside).",
"# radiosity: patch-size 0.4",
"mtllib spot.mtl"]
L=0.1; cx,cz=2.0,-2.0
# room, inward; the ceiling cut around the light: 3x3 grid with the light in the middle
room=list(box((0,0,-4),(4,3,0),'wall','room',inward=True))
for pts,f in room:
    if f=='top':
        xs=[0,cx-L,cx+L,4]; zs=[-4,cz-L,cz+L,0]
        for i in range(3):
            for j in range(3):
                x0,x1=xs[i],xs[i+1]; z0,z1=zs[j],zs[j+1]
                p=[(x0,3,z0),(x1,3,z0),(x1,3,z1),(x0,3,z1)]  # normal: want -y (facing down)
                if nrm(p)[1]>0: p=p[::-1]
                if i==1 and j==1: quad(p,'light','light')
                else: quad(p,'ceiling','ceiling')
    elif f=='bottom': quad(pts,'floor','floor')
    else: quad(pts,'wall','wall_'+f)
for pts,f in box((cx-0.6,0.75,cz-0.6),(cx+0.6,0.8,cz+0.6),'wood','table'):
    quad(pts,'wood','table_'+f)
for pts,f in box((cx-0.05,0.001,cz-0.05),(cx+0.05,0.749,cz+0.05),'wood','pedestal'):
    quad(pts,'wood','pedestal_'+f)
for pts,f in box((0.6,0.001,-1.1),(1.1,0.5,-0.6),'cube','cube'):
    quad(pts,'cube','cube_'+f)
for v in V: out.append("v %g %g %g"%v)
cur=None
for name,mat,idx in F:
    if mat!=cur: out.append("usemtl "+mat); cur=mat
    out.append("o "+name); out.append("f "+" ".join(map(str,idx)))
open(os.path.join(SCENES,'spot.obj'),'w').write("\n".join(out)+"\n")
open(os.path.join(SCENES,'spot.mtl'),'w').write("""# Materials of spot.obj (the adaptive-elements benchmark). Ke: emitted radiance, W/sr/m².
newmtl wall
Kd 0.6 0.6 0.6
newmtl ceiling
Kd 0.7 0.7 0.7
newmtl floor
Kd 0.4 0.4 0.4
newmtl wood
Kd 0.5 0.35 0.2
newmtl cube
Kd 0.3 0.4 0.6
# 0.04 m² at pi x 200 W/m² = 25 W
newmtl light
Kd 0.8 0.8 0.8
Ke 200 200 200
""")
