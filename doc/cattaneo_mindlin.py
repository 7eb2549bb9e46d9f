#!/usr/bin/env python3
"""doc/cattaneo_mindlin.svg from the contact CSV of example/scenes/cattaneo_mindlin.nml.

    sprc run example/scenes/cattaneo_mindlin.nml        # writes out/cattaneo_mindlin_contact.csv
    python3 doc/cattaneo_mindlin.py out/cattaneo_mindlin_contact.csv doc/cattaneo_mindlin.svg

Plots the FE tangential traction on the block, q = -tx_fe (the traction on the roller,
the slave, is -q), over x/a for every level in the CSV, against the Cattaneo-Mindlin
closed form q(x) = mu p0 [sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2)] (second term for
|x| < c) and the slip bound mu p(x), and prints per level the stick zone and the
traction's L2 error. The constants are the scene's (its comment states them).
Standard library only.
"""
import csv
import math
import sys

LOAD, Q, MU, E, NU = 1.0788436, 2 * 0.0809163, 0.3, 1000.0, 0.3
E_STAR = E / (2 * (1 - NU**2))
A = math.sqrt(4 * LOAD / (math.pi * E_STAR))
P0 = 2 * LOAD / (math.pi * A)
C = A * math.sqrt(1 - Q / (MU * LOAD))


def q_exact(x):
    q = MU * P0 * math.sqrt(max(0.0, 1 - (x / A) ** 2))
    if abs(x) < C:
        q -= MU * P0 * (C / A) * math.sqrt(max(0.0, 1 - (x / C) ** 2))
    return q


def read(path):
    levels = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            levels.setdefault(int(r['level']), []).append(
                (float(r['x']), float(r['weight']), r['state'], -float(r['tx_fe'])))
    return levels


def summary(level, pts):
    """Stick zone (outer edges of its contact cells, 2h wide) and L2 error of q."""
    h = 2.0 / 2 ** (level + 6)
    stick = [x for x, _, s, _ in pts if s == 'stick']
    lo = math.floor(min(stick) / (2 * h)) * 2 * h
    hi = math.ceil(max(stick) / (2 * h)) * 2 * h
    err = math.sqrt(sum(w * (q - q_exact(x)) ** 2 for x, w, _, q in pts))
    norm = math.sqrt(sum(w * q_exact(x) ** 2 for x, w, _, _ in pts))
    return h, lo, hi, err / norm


def svg(levels):
    width, height, left, right, top, bottom = 760, 440, 70, 20, 40, 60
    xmin, xmax, ymin, ymax = -1.2, 1.2, -0.05, 1.45

    def px(u):
        return left + (u - xmin) / (xmax - xmin) * (width - left - right)

    def py(v):
        return height - bottom - (v - ymin) / (ymax - ymin) * (height - top - bottom)

    out = ['<?xml version="1.0" encoding="UTF-8" standalone="no"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}">',
           f'<rect x="0" y="0" width="{width}" height="{height}" fill="white"/>',
           '<g font-family="sans-serif" font-size="12" fill="black">',
           f'<text x="{width / 2}" y="22" font-size="15" text-anchor="middle">Cattaneo-Mindlin: tangential '
           f'traction on the block, Q = 0.5 mu P, c/a = {C / A:.4f}</text>']
    for t in [-1.0, -0.5, 0.0, 0.5, 1.0]:
        out.append(f'<line x1="{px(t):.1f}" y1="{py(ymin):.1f}" x2="{px(t):.1f}" y2="{py(ymax):.1f}" '
                   'stroke="#dddddd"/>')
        out.append(f'<text x="{px(t):.1f}" y="{py(ymin) + 16:.1f}" text-anchor="middle">{t:g}</text>')
    for t in [0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4]:
        out.append(f'<line x1="{px(xmin):.1f}" y1="{py(t):.1f}" x2="{px(xmax):.1f}" y2="{py(t):.1f}" '
                   'stroke="#dddddd"/>')
        out.append(f'<text x="{px(xmin) - 6:.1f}" y="{py(t) + 4:.1f}" text-anchor="end">{t:g}</text>')
    for t in [-C / A, C / A]:
        out.append(f'<line x1="{px(t):.1f}" y1="{py(ymin):.1f}" x2="{px(t):.1f}" y2="{py(ymax):.1f}" '
                   'stroke="#888888" stroke-dasharray="2,3"/>')
    out.append(f'<text x="{px(C / A) + 4:.1f}" y="{py(ymax) + 12:.1f}">x = c</text>')
    out.append(f'<rect x="{px(xmin):.1f}" y="{py(ymax):.1f}" width="{px(xmax) - px(xmin):.1f}" '
               f'height="{py(ymin) - py(ymax):.1f}" fill="none" stroke="black"/>')
    out.append(f'<text x="{(px(xmin) + px(xmax)) / 2:.1f}" y="{height - 18}" text-anchor="middle">x / a</text>')
    out.append(f'<text x="18" y="{(py(ymin) + py(ymax)) / 2:.1f}" text-anchor="middle" '
               f'transform="rotate(-90 18 {(py(ymin) + py(ymax)) / 2:.1f})">q / (mu p0)</text>')
    n = 400
    xs = [xmin + (xmax - xmin) * i / n for i in range(n + 1)]
    bound = ' '.join(f'{px(x):.1f},{py(math.sqrt(max(0.0, 1 - x * x))):.1f}' for x in xs)
    exact = ' '.join(f'{px(x):.1f},{py(q_exact(x * A) / (MU * P0)):.1f}' for x in xs)
    out.append(f'<polyline points="{bound}" fill="none" stroke="#999999" stroke-width="1.2" '
               'stroke-dasharray="6,4"/>')
    out.append(f'<polyline points="{exact}" fill="none" stroke="black" stroke-width="2"/>')
    colours = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e']
    legend = [('black', 'closed form (Johnson 7.1)', ''), ('#999999', 'slip bound mu p (Hertz)', '6,4')]
    for k, level in enumerate(sorted(levels)):
        pts = sorted(levels[level])
        colour = colours[k % len(colours)]
        line = ' '.join(f'{px(x / A):.1f},{py(q / (MU * P0)):.1f}' for x, _, s, q in pts
                        if xmin <= x / A <= xmax and s != 'open')
        out.append(f'<polyline points="{line}" fill="none" stroke="{colour}" stroke-width="1.2"/>')
        h, lo, hi, err = summary(level, pts)
        legend.append((colour, f'FE level {level} (a/h = {A / h:.1f}, L2 error {100 * err:.1f} %)', ''))
    for k, (colour, text, dash) in enumerate(legend):
        y = py(ymax) + 20 + 17 * k
        x0 = px(xmin) + 12
        style = f' stroke-dasharray="{dash}"' if dash else ''
        out.append(f'<line x1="{x0:.1f}" y1="{y - 4:.1f}" x2="{x0 + 26:.1f}" y2="{y - 4:.1f}" '
                   f'stroke="{colour}" stroke-width="2"{style}/>')
        out.append(f'<text x="{x0 + 32:.1f}" y="{y:.1f}">{text}</text>')
    out += ['</g>', '</svg>', '']
    return '\n'.join(out)


def main():
    if len(sys.argv) != 3:
        sys.exit('usage: cattaneo_mindlin.py CONTACT_CSV OUTPUT_SVG')
    levels = read(sys.argv[1])
    print(f'a = {A:.6f}, c = {C:.6f}, p0 = {P0:.4f}')
    for level in sorted(levels):
        h, lo, hi, err = summary(level, levels[level])
        c_fe = (hi - lo) / 2
        print(f'level {level}: h = {h:.6f}, a/h = {A / h:.1f}, c/h = {C / h:.1f}, stick zone [{lo:.5f}, {hi:.5f}], '
              f'c_fe = {c_fe:.5f}, |c_fe - c|/h = {abs(c_fe - C) / h:.2f}, ends |x - c|/h = {abs(-lo - C) / h:.2f}, '
              f'{abs(hi - C) / h:.2f}, L2 error of q {100 * err:.1f} %')
    with open(sys.argv[2], 'w') as f:
        f.write(svg(levels))


if __name__ == '__main__':
    main()
