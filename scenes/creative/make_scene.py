#!/usr/bin/env python3
"""Generates wind-garden.xml, rbsim's creative scene: mobiles of non-convex bodies (stars,
crescents, chevrons) hanging from a beam on springs, set spinning, and a string of swallowtail
bunting billowing between two posts, all under gravity in a steady wind. Wind is the only dissipative force: it damps the springs'
swinging toward a balance of gravity, tension and drag, so the motion settles slowly and
keeps shimmering. Rerun to regenerate: python3 make_scene.py > wind-garden.xml"""
import math

PALETTE = [(0.98, 0.36, 0.35), (1.0, 0.70, 0.25), (0.99, 0.86, 0.37), (0.45, 0.85, 0.55),
           (0.30, 0.75, 0.93), (0.55, 0.50, 0.95), (0.93, 0.45, 0.80)]


def signed_area(pts):
    return 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]))


def clockwise(pts):
    return pts if signed_area(pts) < 0 else pts[::-1]


def star(r):
    return [((r if k % 2 == 0 else 0.45 * r) * math.sin(k * math.pi / 5),
             (r if k % 2 == 0 else 0.45 * r) * math.cos(k * math.pi / 5)) for k in range(10)]


def crescent(r):
    outer = [(r * math.cos(a), r * math.sin(a)) for a in [math.radians(d) for d in range(120, -121, -30)]]
    inner = [(0.35 * r + 0.62 * r * math.cos(a), 0.62 * r * math.sin(a))
             for a in [math.radians(d) for d in range(-110, 111, 44)]]
    return outer + inner


def chevron(r):
    return [(-r, 0.5 * r), (0.0, -0.3 * r), (r, 0.5 * r), (r, -0.1 * r), (0.0, -0.9 * r), (-r, -0.1 * r)]


def swallowtail(r):
    return [(-0.6 * r, 0.4 * r), (0.6 * r, 0.4 * r), (0.6 * r, -0.8 * r), (0.0, -0.35 * r), (-0.6 * r, -0.8 * r)]


class Scene:
    def __init__(self):
        self.vertices, self.bodies, self.springs, self.colors, self.spring_colors = [], [], [], [], []

    def body(self, shape, cx, cy, color, radius=0.06, omega=0.0):
        pts = clockwise(shape)
        # unit vertex masses: the centre of mass is the mean of the vertices
        mx = sum(x for x, _ in pts) / len(pts)
        my = sum(y for _, y in pts) / len(pts)
        first = len(self.vertices)
        self.vertices += [(cx + x - mx, cy + y - my) for x, y in pts]
        self.bodies.append((list(range(first, first + len(pts))), radius, omega))
        self.colors.append(color)
        lo = min(y - my for _, y in pts)
        hi = max(y - my for _, y in pts)
        return len(self.bodies) - 1, lo, hi, (mx, my)

    def spring(self, i, pi, j, pj, k, l0, color):
        self.springs.append((i, pi, j, pj, k, l0))
        self.spring_colors.append(color)

    def xml(self):
        out = ['<scene>',
               '  <simtype type="rigid-body"/>',
               '  <description text="Wind garden: mobiles of stars, crescents and chevrons hang from a beam and '
               'paper darts strain at their tethers, all in one steady wind. rbsim creative scene."/>',
               '  <duration time="20.0"/>',
               '  <viewport cx="0.0" cy="1.6" size="8.5"/>',
               '  <backgroundcolor r="0.05" g="0.06" b="0.14"/>',
               '  <rigidbodyintegrator type="symplectic-euler" dt="0.002"/>']
        out += [f'  <rigidbodyvertex x="{x:.6f}" y="{y:.6f}" m="1"/>' for x, y in self.vertices]
        for ids, r, omega in self.bodies:
            ps = ' '.join(f'p="{i}"' for i in ids)
            out.append(f'  <rigidbody {ps} vx="0.0" vy="0.0" omega="{omega}" r="{r}"/>')
        for i, (a, b), j, (c, d), k, l0 in self.springs:
            out.append(f'  <rigidbodyspringforce i="{i}" pix="{a:.6f}" piy="{b:.6f}" j="{j}" pjx="{c:.6f}" '
                       f'pjy="{d:.6f}" k="{k}" l0="{l0}"/>')
        out.append('  <rigidbodygravityforce fx="0.0" fy="-2.5"/>')
        out.append('  <rigidbodywindforce beta="0.45" fx="6.0" fy="0.8" pointsperedge="3"/>')
        for n, (r, g, b) in enumerate(self.colors):
            out.append(f'  <rigidbodycolor body="{n}" r="{r}" g="{g}" b="{b}"/>')
        for n, (r, g, b) in enumerate(self.spring_colors):
            out.append(f'  <rigidbodyspringcolor spring="{n}" r="{r}" g="{g}" b="{b}"/>')
        out.append('</scene>')
        return '\n'.join(out) + '\n'


def main():
    s = Scene()
    thread = (0.80, 0.82, 0.90)
    shapes = [star, crescent, chevron]
    beam_y = 7.8
    for m, x in enumerate([-12.0, -8.0, -4.0, 0.0, 4.0, 8.0, 12.0]):
        above, above_lo, y = -1, 0.0, beam_y
        for level in range(3):
            size = 0.95 - 0.15 * level
            shape = shapes[(m + level) % 3](size)
            y -= 1.2 + size
            spin = (2.5 - level) * (1 if (m + level) % 2 else -1)
            b, lo, hi, _ = s.body(shape, x, y, PALETTE[(m + 2 * level) % len(PALETTE)], omega=spin)
            if above < 0:
                s.spring(-1, (x, beam_y), b, (0.0, hi), 60.0, 0.5, thread)
            else:
                s.spring(above, (0.0, above_lo), b, (0.0, hi), 40.0, 0.35, thread)
            above, above_lo = b, lo
            y -= size
    # Bunting: swallowtail pennants strung corner to corner between two posts.
    gold = (0.95, 0.80, 0.45)
    left, right, flags = (-14.0, -2.0), (14.0, -3.0), 11
    previous, previous_corner = -1, left
    for n in range(flags):
        f = (n + 0.5) / flags
        cx = left[0] + f * (right[0] - left[0])
        cy = left[1] + f * (right[1] - left[1]) - 1.5 * math.sin(math.pi * f) - 0.4
        b, lo, hi, (mx, my) = s.body(swallowtail(1.0), cx, cy, PALETTE[(2 * n) % len(PALETTE)], radius=0.04)
        top_left, top_right = (-0.6 - mx, 0.4 - my), (0.6 - mx, 0.4 - my)
        s.spring(previous, previous_corner, b, top_left, 900.0, 0.55, gold)
        previous, previous_corner = b, top_right
    s.spring(previous, previous_corner, -1, right, 900.0, 0.55, gold)
    print(s.xml(), end='')


if __name__ == '__main__':
    main()
