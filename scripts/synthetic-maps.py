#!/usr/bin/env python3
"""Writes the synthetic 1024x512 Radiance HDR maps of the README's concentrated-target
table (no dependencies): sun50.hdr (a constant map whose 2x2-pixel block holds half
the light), lowsun.hdr (a 3x3-pixel sun 4 degrees above the horizon holding 80 %),
lamps.hdr (a dark room with four 2x1-pixel lamps of 15 % each), pixel.hdr (one lit
pixel, 30 degrees above the horizon, the rest black: half the normals see no light),
sky.hdr (a sky brightening towards the horizon with a 3x3-pixel sun 30 degrees up
holding 5/7 of the light, above a black ground); sun45.hdr and sun20.hdr (clear
skies as most outdoor HDRIs are: a sky brightening towards the horizon above a
ground of 0.3 and 0.2, and a 2x2-pixel sun, 0.7 degrees, 45 and 20 degrees up,
holding 80 % and 90 % of the light); and lamps-4k.hdr, a 4096x2048 map
of lamps.hdr's room whose four lamps are 2x1 pixels of that map (0.09 degrees), for
the bake of a large map (docs/results/envmap.md#large-maps).
Usage: scripts/synthetic-maps.py OUT_DIR"""
import math, os, sys
out=sys.argv[1] if len(sys.argv)>1 else 'out/maps'
os.makedirs(out,exist_ok=True)
W,H=1024,512
def rgbe(v):
    if v<=1e-32: return b'\0\0\0\0'
    m,e=math.frexp(v)
    x=min(int(m*256.0),255)
    return bytes([x,x,x,e+128])
def write(path,f):
    out=bytearray()
    out+=b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n"%(H,W)
    for r in range(H):
        row=bytearray()
        for c in range(W):
            row+=rgbe(f(c,r))
        out+=row
    open(path,'wb').write(out)
def omega(r): return (2*math.pi/W)*(math.cos(math.pi*r/H)-math.cos(math.pi*(r+1)/H))
# 1. uniform + 2x2 block with 50% of mass
rows=[118,119]; cols=[613,614]
bg=4*math.pi
blockom=sum(omega(r) for r in rows)*2
Ls=(bg-blockom)/blockom  # block mass = Ls*blockom = bg - blockom -> half of total
write(os.path.join(out,'sun50.hdr'), lambda c,r: Ls if (r in rows and c in cols) else 1.0)
# 2. low sun: sky 1.0 above horizon, ground 0.2, sun 3x3 at row 244..246 col 300..302 holding ~80%
srows=[244,245,246]; scols=[300,301,302]
sky=sum(omega(r) for r in range(256))*W*1.0+sum(omega(r) for r in range(256,512))*W*0.2
som=sum(omega(r) for r in srows)*3
Ls2=4*sky/som
write(os.path.join(out,'lowsun.hdr'), lambda c,r: Ls2 if (r in srows and c in scols) else (1.0 if r<256 else 0.2))
# 3. lamps: dark room 0.05, 4 lamps 2x1 px each holding ~15% each
lamps=[(100,60),(400,150),(700,200),(900,90)]
base=0.05*4*math.pi
def lampf(c,r):
    for (lc,lr) in lamps:
        if r==lr and c in (lc,lc+1): return 0.15/0.4*base/(2*omega(lr))
    return 0.05
write(os.path.join(out,'lamps.hdr'), lampf)
# 4. one lit pixel, the rest black
write(os.path.join(out,'pixel.hdr'), lambda c,r: 100.0 if (r,c)==(170,500) else 0.0)
# 5. sky above a black ground, a 3x3 sun 30 degrees up holding 2.5 times the sky's light
srows=[170,171,172]; scols=[500,501,502]
skym=sum(omega(r)*(1+r/256) for r in range(256))*W
Ls5=2.5*skym/(sum(omega(r) for r in srows)*3)
write(os.path.join(out,'sky.hdr'), lambda c,r: Ls5 if (r in srows and c in scols) else ((1+r/256) if r<256 else 0.0))
# 6. clear skies: a 2x2-pixel sun `elev` degrees up holding `share` of the light,
# a sky from 0.5 at the zenith to 1 at the horizon, a uniform ground
def sunmap(path,elev,share,ground):
    rs=int((90-elev)/180*H); rows=[rs,rs+1]; cols=[300,301]
    sky=lambda r: 0.5+0.5*r/256 if r<256 else ground
    rest=sum(omega(r)*sky(r) for r in range(H))*W
    Ls=share/(1-share)*rest/(sum(omega(r) for r in rows)*2)
    write(os.path.join(out,path), lambda c,r: Ls if (r in rows and c in cols) else sky(r))
sunmap('sun45.hdr',45,0.8,0.3)
sunmap('sun20.hdr',20,0.9,0.2)
# 7. lamps at 4096 x 2048: the dark room, four 2x1-pixel lamps of ~15 % each, rows
# written whole (the other maps' per-pixel function would take minutes here)
W4,H4=4096,2048
def omega4(r): return (2*math.pi/W4)*(math.cos(math.pi*r/H4)-math.cos(math.pi*(r+1)/H4))
lamps4=[(401,241),(1602,601),(2803,802),(3601,361)]
big=bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n"%(H4,W4))
for r in range(H4):
    row=bytearray(rgbe(0.05)*W4)
    for (lc,lr) in lamps4:
        if r==lr:
            v=rgbe(0.15/0.4*base/(2*omega4(lr)))
            row[4*lc:4*lc+8]=v+v
    big+=row
open(os.path.join(out,'lamps-4k.hdr'),'wb').write(big)
