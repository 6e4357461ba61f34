#!/usr/bin/env python3
# Writes test/data/bad_scenes/*.xml from one valid template, one line broken per file, and the
# MANIFEST of expected errors (line numbers are those of the template, by construction).
import os
T = [
 '<scene>',                                                                                  # 1
 '  <simtype type="rigid-body"/>',                                                           # 2
 '  <duration time="1.0"/>',                                                                 # 3
 '  <rigidbodyintegrator type="symplectic-euler" dt="0.01"/>',                               # 4
 '  <rigidbodyvertex x="-1" y="-1" m="1"/>',                                                 # 5
 '  <rigidbodyvertex x="-1" y=" 1" m="1"/>',                                                 # 6
 '  <rigidbodyvertex x=" 1" y=" 1" m="1"/>',                                                 # 7
 '  <rigidbodyvertex x=" 1" y="-1" m="1"/>',                                                 # 8
 '  <rigidbody p="0" p="1" p="2" p="3" vx="0" vy="0" omega="0" r="0.1"/>',                   # 9
 '  <rigidbodyspringforce i="0" pix="1" piy="0" j="-1" pjx="3" pjy="0" k="1" l0="1"/>',      # 10
 '  <rigidbodygravityforce fx="0" fy="-9.81"/>',                                             # 11
 '  <rigidbodywindforce beta="1" fx="1" fy="0" pointsperedge="2"/>',                         # 12
 '  <rigidbodycolor body="0" r="0.1" g="0.2" b="0.3"/>',                                     # 13
 '  <rigidbodyspringcolor spring="0" r="0.5" g="0.5" b="0.5"/>',                             # 14
 '</scene>',                                                                                 # 15
]
def edit(line, old, new):
    t = list(T)
    assert old in t[line - 1], (line, old)
    t[line - 1] = t[line - 1].replace(old, new, 1)
    return '\n'.join(t) + '\n'

# name: (text, line, mode, expected)   mode '=' exact tail after "path:line: ", '^' prefix
cases = {}
def case(name, text, line, mode, expected):
    cases[name] = (text, line, mode, expected)

case('empty', '', 1, '=', 'empty file (expected a <scene>)')
case('not_xml', 'this is not a scene file\n', 1, '=', 'not well-formed XML: XML_ERROR_PARSING_TEXT')
case('truncated', '\n'.join(T[:9]) + '\n  <rigidbodyspringforce i="0" pix="1" piy', 10, '=',
     'not well-formed XML: XML_ERROR_PARSING_ATTRIBUTE (XMLElement name=rigidbodyspringforce)')
case('unclosed_scene', '\n'.join(T[:14]) + '\n', 1, '=', 'not well-formed XML: XML_ERROR_PARSING')
case('wrong_root', '<world>\n' + '\n'.join(T[1:14]) + '\n</world>\n', 1, '=', '<world>: root node must be <scene>')
case('missing_attribute', edit(9, ' r="0.1"', ''), 9, '=', "<rigidbody> attribute 'r': required attribute is missing")
case('missing_mass', edit(6, ' m="1"', ''), 6, '=', "<rigidbodyvertex> attribute 'm': required attribute is missing")
case('non_numeric', edit(7, 'x=" 1"', 'x="one"'), 7, '=', "<rigidbodyvertex> attribute 'x': must be a number (got \"one\")")
case('non_numeric_trailing', edit(11, 'fy="-9.81"', 'fy="-9.81m"'), 11, '=', "<rigidbodygravityforce> attribute 'fy': must be a number (got \"-9.81m\")")
case('nan', edit(5, 'x="-1"', 'x="nan"'), 5, '=', "<rigidbodyvertex> attribute 'x': must be a finite number (got \"nan\")")
case('inf', edit(12, 'fx="1"', 'fx="inf"'), 12, '=', "<rigidbodywindforce> attribute 'fx': must be a finite number (got \"inf\")")
case('overflow', edit(9, 'vx="0"', 'vx="1e999"'), 9, '=', "<rigidbody> attribute 'vx': must be a finite number (got \"1e999\")")
case('mass_zero', edit(8, 'm="1"', 'm="0"'), 8, '=', "<rigidbodyvertex> attribute 'm': must be > 0 (got 0)")
case('mass_negative', edit(5, 'm="1"', 'm="-2.5"'), 5, '=', "<rigidbodyvertex> attribute 'm': must be > 0 (got -2.5)")
case('radius_zero', edit(9, 'r="0.1"', 'r="0"'), 9, '=', "<rigidbody> attribute 'r': must be > 0 (got 0)")
case('radius_negative', edit(9, 'r="0.1"', 'r="-0.1"'), 9, '=', "<rigidbody> attribute 'r': must be > 0 (got -0.1)")
case('dt_zero', edit(4, 'dt="0.01"', 'dt="0"'), 4, '=', "<rigidbodyintegrator> attribute 'dt': must be > 0 (got 0)")
case('dt_negative', edit(4, 'dt="0.01"', 'dt="-0.01"'), 4, '=', "<rigidbodyintegrator> attribute 'dt': must be > 0 (got -0.01)")
case('duration_negative', edit(3, 'time="1.0"', 'time="-1"'), 3, '=', "<duration> attribute 'time': must be >= 0 (got -1)")
case('unknown_integrator', edit(4, 'symplectic-euler', 'runge-kutta'), 4, '=',
     "<rigidbodyintegrator> attribute 'type': unknown integrator \"runge-kutta\" (expected explicit-euler or symplectic-euler)")
case('unknown_simtype', edit(2, 'rigid-body', 'fluid'), 2, '=', "<simtype> attribute 'type': unknown simtype \"fluid\" (expected 'rigid-body')")
case('particle_simtype', edit(2, 'rigid-body', 'particle-system'), 2, '^', "<simtype> attribute 'type': simtype 'particle-system' is not supported")
case('vertex_index_high', edit(9, 'p="3"', 'p="4"'), 9, '=', "<rigidbody> attribute 'p': vertex index 4 out of range [0, 3]")
case('vertex_index_negative', edit(9, 'p="0"', 'p="-1"'), 9, '=', "<rigidbody> attribute 'p': vertex index -1 out of range [0, 3]")
case('vertex_index_not_integer', edit(9, 'p="2"', 'p="2.5"'), 9, '=', "<rigidbody> attribute 'p': must be an integer (got \"2.5\")")
case('one_hull_vertex', edit(9, 'p="0" p="1" p="2" p="3"', 'p="2"'), 9, '=', "<rigidbody> attribute 'p': a rigid body needs at least 2 hull vertices (got 1)")
case('no_hull_vertex', edit(9, 'p="0" p="1" p="2" p="3" ', ''), 9, '=', "<rigidbody> attribute 'p': a rigid body needs at least 2 hull vertices (got 0)")
case('coincident_vertices', edit(9, 'p="0" p="1" p="2" p="3"', 'p="1" p="1"'), 9, '=', "<rigidbody> attribute 'p': all hull vertices coincide (the body has no moment of inertia)")
case('spring_body_high', edit(10, 'j="-1"', 'j="1"'), 10, '=', "<rigidbodyspringforce> attribute 'j': body index 1 out of range [-1, 0] (-1 = fixed point)")
case('spring_body_minus_two', edit(10, 'i="0"', 'i="-2"'), 10, '=', "<rigidbodyspringforce> attribute 'i': body index -2 out of range [-1, 0] (-1 = fixed point)")
case('spring_k_negative', edit(10, 'k="1"', 'k="-1"'), 10, '=', "<rigidbodyspringforce> attribute 'k': must be >= 0 (got -1)")
case('spring_l0_negative', edit(10, 'l0="1"', 'l0="-0.5"'), 10, '=', "<rigidbodyspringforce> attribute 'l0': must be >= 0 (got -0.5)")
case('color_body_high', edit(13, 'body="0"', 'body="1"'), 13, '=', "<rigidbodycolor> attribute 'body': body index 1 out of range [0, 0]")
case('color_body_negative', edit(13, 'body="0"', 'body="-1"'), 13, '=', "<rigidbodycolor> attribute 'body': body index -1 out of range [0, 0]")
case('spring_color_high', edit(14, 'spring="0"', 'spring="1"'), 14, '=', "<rigidbodyspringcolor> attribute 'spring': spring index 1 out of range [0, 0]")
case('points_per_edge_one', edit(12, 'pointsperedge="2"', 'pointsperedge="1"'), 12, '=',
     "<rigidbodywindforce> attribute 'pointsperedge': must be an integer in [2, 1000000] (got 1)")
case('points_per_edge_zero', edit(12, 'pointsperedge="2"', 'pointsperedge="0"'), 12, '=',
     "<rigidbodywindforce> attribute 'pointsperedge': must be an integer in [2, 1000000] (got 0)")
case('beta_negative', edit(12, 'beta="1"', 'beta="-0.5"'), 12, '=', "<rigidbodywindforce> attribute 'beta': must be >= 0 (got -0.5)")
case('color_above_one', edit(13, 'r="0.1"', 'r="1.5"'), 13, '=', "<rigidbodycolor> attribute 'r': colour component must be in [0, 1] (got 1.5)")
case('color_below_zero', edit(14, 'g="0.5"', 'g="-0.1"'), 14, '=', "<rigidbodyspringcolor> attribute 'g': colour component must be in [0, 1] (got -0.1)")
case('duplicate_node', edit(3, '<duration time="1.0"/>', '<duration time="1.0"/><duration time="2.0"/>'), 3, '=',
     '<duration>: node may appear only once (first at line 3)')
case('duplicate_attribute', edit(4, 'dt="0.01"', 'dt="0.01" dt="0.02"'), 4, '=', "<rigidbodyintegrator> attribute 'dt': attribute given more than once")
case('missing_integrator', '\n'.join(T[:3] + [''] + T[4:]) + '\n', 1, '=', '<scene>: missing node <rigidbodyintegrator>')
case('missing_duration', '\n'.join(T[:2] + [''] + T[3:]) + '\n', 1, '=', '<scene>: missing node <duration>')

out = os.path.dirname(os.path.abspath(__file__))
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, 'MANIFEST'), 'w') as m:
    m.write('# Bad scenes and the error each must give: file | line | mode | message after "<path>:<line>: "\n')
    m.write('# mode "=": the message is exactly this; "^": it starts with this. Read by test/scene and test/cli.\n')
    for name, (text, line, mode, expected) in cases.items():
        with open(os.path.join(out, name + '.xml'), 'w') as f:
            f.write(text)
        m.write(f'{name}.xml | {line} | {mode} | {expected}\n')
    m.write('directory.xml | 0 | = | is a directory, not a scene file\n')
with open(os.path.join(out, 'valid.xml.template'), 'w') as f:
    f.write('\n'.join(T) + '\n')
print(len(cases))
