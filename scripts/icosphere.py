#!/usr/bin/env python3
# An icosphere of radius 1 as binary PLY, for the curvature accuracy table in
# docs/curvature.md: an icosahedron subdivided LEVELS times, vertices on the sphere.
#   scripts/icosphere.py LEVELS OUT.ply
import struct, math, sys
def icosphere(R, levels):
    t=(1+5**0.5)/2
    P=[(-1,t,0),(1,t,0),(-1,-t,0),(1,-t,0),(0,-1,t),(0,1,t),(0,-1,-t),(0,1,-t),(t,0,-1),(t,0,1),(-t,0,-1),(-t,0,1)]
    T=[0,11,5,0,5,1,0,1,7,0,7,10,0,10,11,1,5,9,5,11,4,11,10,2,10,7,6,7,1,8,3,9,4,3,4,2,3,2,6,3,6,8,3,8,9,4,9,5,2,4,11,6,2,10,8,6,7,9,8,1]
    P=[list(p) for p in P]
    for l in range(levels):
        mid={}
        def m(a,b):
            k=(min(a,b),max(a,b))
            if k in mid: return mid[k]
            P.append([(P[a][i]+P[b][i])/2 for i in range(3)]); mid[k]=len(P)-1; return mid[k]
        F=[]
        for f in range(0,len(T),3):
            a,b,c=T[f:f+3]; ab,bc,ca=m(a,b),m(b,c),m(c,a)
            F+=[a,ab,ca,b,bc,ab,c,ca,bc,ab,bc,ca]
        T=F
    P=[[x*R/math.sqrt(sum(y*y for y in p)) for x in p] for p in P]
    return P,T
P,T=icosphere(1.0,int(sys.argv[1]))
out=bytearray(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(P)}\nproperty float x\nproperty float y\nproperty float z\nelement face {len(T)//3}\nproperty list uchar uint vertex_indices\nend_header\n".encode())
for p in P: out+=struct.pack('<3f',*p)
for f in range(0,len(T),3): out+=struct.pack('<B3I',3,*T[f:f+3])
open(sys.argv[2],'wb').write(out)
