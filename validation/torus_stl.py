# The torus of crates/urdf-inertia/examples/make_large_inputs.rs (`meshes`), binary STL only:
# usage: python3 torus_stl.py FACES OUT.stl
import sys, numpy as np
faces=int(sys.argv[1]); out=sys.argv[2]
m=max(int(round((faces/4.0)**0.5)),3); n=2*m
tau=2*np.pi
i=np.arange(n); j=np.arange(m)
u=tau*i/n; w=tau*j/m
r=1.0+0.3*np.cos(w)
V=np.empty((n,m,3)); V[:,:,0]=np.outer(np.cos(u),r); V[:,:,1]=np.outer(np.sin(u),r); V[:,:,2]=0.3*np.sin(w)[None,:]
V=V.reshape(-1,3)
I,J=np.meshgrid(i,j,indexing='ij')
at=lambda a,b:(a%n)*m+b%m
a=at(I,J); b=at(I+1,J); c=at(I+1,J+1); d=at(I,J+1)
F=np.empty((n,m,2,3),dtype=np.int64)
F[:,:,0,0]=a;F[:,:,0,1]=b;F[:,:,0,2]=c
F[:,:,1,0]=a;F[:,:,1,1]=c;F[:,:,1,2]=d
F=F.reshape(-1,3)
rec=np.zeros(len(F),dtype=[('n','<f4',3),('v','<f4',(3,3)),('a','<u2')])
rec['v']=V[F].astype('<f4')
with open(out,'wb') as fh:
    h=b'torus'+b'\0'*75; fh.write(h); fh.write(np.uint32(len(F)).tobytes()); fh.write(rec.tobytes())
print(len(F),"faces")
