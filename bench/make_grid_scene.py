#!/usr/bin/env python3
"""Writes a FOSSSim scene of N octagons on a grid (gravity, wind with 4 points per edge, one
spring per body to its neighbour) for benchmarks: make_grid_scene.py N STEPS_DT DURATION > scene.xml"""
import math
import sys

n = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
dt = float(sys.argv[2]) if len(sys.argv) > 2 else 0.001
duration = float(sys.argv[3]) if len(sys.argv) > 3 else 2.0
cols = max(1, int(math.ceil(math.sqrt(n))))
out = ['<scene>', '  <simtype type="rigid-body"/>', f'  <duration time="{duration}"/>',
       f'  <rigidbodyintegrator type="symplectic-euler" dt="{dt}"/>']
bodies = []
for b in range(n):
    cx, cy = 3.0 * (b % cols), 3.0 * (b // cols)
    first = 8 * b
    for k in range(8):
        a = -2.0 * math.pi * k / 8  # clockwise
        out.append(f'  <rigidbodyvertex x="{cx + math.cos(a):.9f}" y="{cy + math.sin(a):.9f}" m="1"/>')
    ps = ' '.join(f'p="{first + k}"' for k in range(8))
    bodies.append(f'  <rigidbody {ps} vx="{0.1 * (b % 7)}" vy="0.0" omega="{0.01 * (b % 11)}" r="0.05"/>')
out += bodies
for b in range(n - 1):
    out.append(f'  <rigidbodyspringforce i="{b}" pix="0.5" piy="0.0" j="{b + 1}" pjx="-0.5" pjy="0.0" k="10.0" l0="2.0"/>')
out.append('  <rigidbodygravityforce fx="0.0" fy="-9.81"/>')
out.append('  <rigidbodywindforce beta="0.5" fx="2.0" fy="0.5" pointsperedge="4"/>')
out.append('</scene>')
print('\n'.join(out))
