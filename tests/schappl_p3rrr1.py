"""SchapplM's published P3RRR1 model (robsynth-parroblib), transliterated for a peer check.

Two functions of https://github.com/SchapplM/robsynth-parroblib (commit 01c8d77, folder
``sym_2T1R/P3RRR1``), generated there by Maple (HybrDyn toolbox, 2019-05-03): their
straight-line bodies, transliterated mechanically from MATLAB to Python (1-based indices made
0-based, ``^`` made ``**``, the result made a NumPy array); nothing else of that repository is
used or kept here.

- :func:`invdyn_platform`: ``hd_G1A0/P3RRR1G1A0_invdyn_para_pf_slag_vp1.m``, the inverse dynamics
  in platform coordinates ``tauX`` (forces along x0, y0 and the moment about z0 at the platform
  frame's origin that produce ``xDDP``: ``M xDDP + c`` in rpr3gen's terms, ``J^T tau``).
- :func:`jacobian_inverse`: ``hd_G1P1A1/P3RRR1G1P1A1_Jinv.m``, the actuated joint rates per
  platform rate (motors on joint 1 of each leg): rpr3gen's actuator Jacobian ``J``.

Their conventions (from the functions' documentation and the robot's definition): three
identical RRR legs (``S3RRR1``, modified Denavit-Hartenberg) with link lengths
``pkin = [a2, a3, d1, d2, d3]``; leg ``i``'s base frame turned by ``legFrame[i, 2]`` about z0
(its position does not enter); joint angles ``qJ[0, i]`` (link 1 from the base frame's x axis)
and ``qJ[1, i]`` (link 2 from link 1); link k's frame at its first joint with x towards the next
joint; ``koppelP[i]`` the platform joint in the platform frame; masses ``m`` (link 1, link 2,
platform), centres of mass ``rSges`` in the body frames and inertias about them ``Icges``
(``xx yy zz xy xz yz``); ``g`` the gravitational acceleration; ``xP = (x, y, phi)``.

Copyright (c) 2020 Moritz Schappler, Leibniz Universitaet Hannover; MIT License:

    Permission is hereby granted, free of charge, to any person obtaining a copy of this
    software and associated documentation files (the "Software"), to deal in the Software
    without restriction, including without limitation the rights to use, copy, modify, merge,
    publish, distribute, sublicense, and/or sell copies of the Software, and to permit persons
    to whom the Software is furnished to do so, subject to the following conditions: The above
    copyright notice and this permission notice shall be included in all copies or substantial
    portions of the Software. THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND,
    EXPRESS OR IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS
    FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT
    HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER IN AN ACTION OF
    CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE
    USE OR OTHER DEALINGS IN THE SOFTWARE.
"""

# ruff: noqa: E501
# fmt: off

from __future__ import annotations

import numpy as np
from numpy import cos, sin


def invdyn_platform(xP, xDP, xDDP, qJ, g, legFrame, koppelP, pkin, m, rSges, Icges) -> np.ndarray:
    """``tauX`` (3,) at one state; arrays as documented in the module (0-based)."""
    t181 = 0.1e1 / pkin[1]
    t183 = 0.1e1 / pkin[0]
    t215 = t181 * t183
    t151 = qJ[0, 2] + qJ[1, 2]
    t131 = sin(t151)
    t134 = cos(t151)
    t160 = sin(qJ[0, 2])
    t163 = cos(qJ[0, 2])
    t234 = 0.1e1 / (t131 * t163 - t134 * t160)
    t207 = t234 * t215
    t154 = legFrame[2, 2]
    t137 = sin(t154)
    t140 = cos(t154)
    t94 = t131 * t140 + t134 * t137
    t67 = pkin[0] * (t137 * t163 + t140 * t160) + t94 * pkin[1]
    t95 = -t131 * t137 + t134 * t140
    t70 = pkin[0] * (-t137 * t160 + t140 * t163) + t95 * pkin[1]
    t169 = xP[2]
    t148 = sin(t169)
    t149 = cos(t169)
    t172 = koppelP[2, 1]
    t175 = koppelP[2, 0]
    t114 = -t148 * t172 + t149 * t175
    t166 = xDP[2]
    t167 = xDP[1]
    t88 = t114 * t166 + t167
    t111 = t148 * t175 + t149 * t172
    t168 = xDP[0]
    t91 = -t111 * t166 + t168
    t31 = (-t67 * t88 - t70 * t91) * t207
    t152 = qJ[0, 1] + qJ[1, 1]
    t132 = sin(t152)
    t135 = cos(t152)
    t161 = sin(qJ[0, 1])
    t164 = cos(qJ[0, 1])
    t233 = 0.1e1 / (t132 * t164 - t135 * t161)
    t205 = t233 * t215
    t155 = legFrame[1, 2]
    t138 = sin(t155)
    t141 = cos(t155)
    t96 = t132 * t141 + t135 * t138
    t68 = pkin[0] * (t138 * t164 + t141 * t161) + t96 * pkin[1]
    t97 = -t132 * t138 + t135 * t141
    t71 = pkin[0] * (-t138 * t161 + t141 * t164) + t97 * pkin[1]
    t173 = koppelP[1, 1]
    t176 = koppelP[1, 0]
    t115 = -t148 * t173 + t149 * t176
    t89 = t115 * t166 + t167
    t112 = t148 * t176 + t149 * t173
    t92 = -t112 * t166 + t168
    t32 = (-t68 * t89 - t71 * t92) * t205
    t153 = qJ[0, 0] + qJ[1, 0]
    t133 = sin(t153)
    t136 = cos(t153)
    t162 = sin(qJ[0, 0])
    t165 = cos(qJ[0, 0])
    t232 = 0.1e1 / (t133 * t165 - t136 * t162)
    t203 = t232 * t215
    t156 = legFrame[0, 2]
    t139 = sin(t156)
    t142 = cos(t156)
    t98 = t133 * t142 + t136 * t139
    t69 = pkin[0] * (t139 * t165 + t142 * t162) + t98 * pkin[1]
    t99 = -t133 * t139 + t136 * t142
    t72 = pkin[0] * (-t139 * t162 + t142 * t165) + t99 * pkin[1]
    t174 = koppelP[0, 1]
    t177 = koppelP[0, 0]
    t116 = -t148 * t174 + t149 * t177
    t90 = t116 * t166 + t167
    t113 = t148 * t177 + t149 * t174
    t93 = -t113 * t166 + t168
    t33 = (-t69 * t90 - t72 * t93) * t203
    t221 = t233 * t183
    t222 = t234 * t183
    t43 = (t88 * t94 + t91 * t95) * t222
    t237 = 0.2e1 * t43 + t31
    t44 = (t89 * t96 + t92 * t97) * t221
    t236 = 0.2e1 * t44 + t32
    t220 = t232 * t183
    t45 = (t90 * t98 + t93 * t99) * t220
    t235 = 0.2e1 * t45 + t33
    t184 = (t133 * t162 + t136 * t165) * pkin[0]
    t185 = (t132 * t161 + t135 * t164) * pkin[0]
    t186 = (t131 * t160 + t134 * t163) * pkin[0]
    t22 = t43 + t31
    t231 = t22 * t31
    t23 = t44 + t32
    t230 = t23 * t32
    t24 = t45 + t33
    t229 = t24 * t33
    t228 = t234 * t94
    t227 = t234 * t95
    t226 = t233 * t96
    t225 = t233 * t97
    t224 = t232 * t98
    t223 = t232 * t99
    t219 = t234 * t181
    t218 = t233 * t181
    t217 = t232 * t181
    t146 = rSges[1, 0] ** 2 + rSges[1, 1] ** 2
    t129 = m[1] * t146 + Icges[1, 2]
    t216 = t129 * t181
    t214 = t67 * t219
    t213 = t70 * t219
    t212 = t68 * t218
    t211 = t71 * t218
    t210 = t69 * t217
    t209 = t72 * t217
    t208 = t234 * t216
    t206 = t233 * t216
    t204 = t232 * t216
    t202 = (rSges[0, 0] ** 2 + rSges[0, 1] ** 2) * m[0] + Icges[0, 2] + Icges[1, 2]
    t117 = -g[0] * t137 + g[1] * t140
    t120 = g[0] * t140 + g[1] * t137
    t201 = t131 * (rSges[1, 0] * t120 + rSges[1, 1] * t117) - t134 * (rSges[1, 0] * t117 - rSges[1, 1] * t120)
    t118 = -g[0] * t138 + g[1] * t141
    t121 = g[0] * t141 + g[1] * t138
    t200 = t132 * (rSges[1, 0] * t121 + rSges[1, 1] * t118) - t135 * (rSges[1, 0] * t118 - rSges[1, 1] * t121)
    t119 = -g[0] * t139 + g[1] * t142
    t122 = g[0] * t142 + g[1] * t139
    t199 = t133 * (rSges[1, 0] * t122 + rSges[1, 1] * t119) - t136 * (rSges[1, 0] * t119 - rSges[1, 1] * t122)
    t150 = t166 ** 2
    t157 = xDDP[2]
    t158 = xDDP[1]
    t73 = -t111 * t150 + t114 * t157 + t158
    t159 = xDDP[0]
    t76 = -t111 * t157 - t114 * t150 + t159
    t195 = t183 * (t67 * t73 + t70 * t76)
    t74 = -t112 * t150 + t115 * t157 + t158
    t77 = -t112 * t157 - t115 * t150 + t159
    t194 = t183 * (t68 * t74 + t71 * t77)
    t75 = -t113 * t150 + t116 * t157 + t158
    t78 = -t113 * t157 - t116 * t150 + t159
    t193 = t183 * (t69 * t75 + t72 * t78)
    t192 = t183 * (t73 * t94 + t76 * t95)
    t191 = t183 * (t74 * t96 + t77 * t97)
    t190 = t183 * (t75 * t98 + t78 * t99)
    t123 = -rSges[1, 0] * t160 + rSges[1, 1] * t163
    t126 = rSges[1, 0] * t163 + rSges[1, 1] * t160
    t189 = (-t123 * t131 + t126 * t134) * pkin[0]
    t124 = -rSges[1, 0] * t161 + rSges[1, 1] * t164
    t127 = rSges[1, 0] * t164 + rSges[1, 1] * t161
    t188 = (-t124 * t132 + t127 * t135) * pkin[0]
    t125 = -rSges[1, 0] * t162 + rSges[1, 1] * t165
    t128 = rSges[1, 0] * t165 + rSges[1, 1] * t162
    t187 = (-t125 * t133 + t128 * t136) * pkin[0]
    t182 = pkin[0] ** 2
    t180 = pkin[1] ** 2
    t171 = rSges[2, 0]
    t170 = rSges[2, 1]
    t130 = t182 + t146
    t110 = -t148 * t170 + t149 * t171
    t109 = t148 * t171 + t149 * t170
    t81 = -t125 * t136 - t128 * t133
    t80 = -t124 * t135 - t127 * t132
    t79 = -t123 * t134 - t126 * t131
    t66 = Icges[1, 2] + (t146 + t187) * m[1]
    t65 = Icges[1, 2] + (t146 + t188) * m[1]
    t64 = Icges[1, 2] + (t146 + t189) * m[1]
    t63 = (t130 + 0.2e1 * t187) * m[1] + t202
    t62 = (t130 + 0.2e1 * t188) * m[1] + t202
    t61 = (t130 + 0.2e1 * t189) * m[1] + t202
    t48 = (-t113 * t99 + t116 * t98) * t220
    t47 = (-t112 * t97 + t115 * t96) * t221
    t46 = (-t111 * t95 + t114 * t94) * t222
    t42 = (-t113 * t72 + t116 * t69) * t203
    t41 = (-t112 * t71 + t115 * t68) * t205
    t40 = (-t111 * t70 + t114 * t67) * t207
    t18 = -t129 * t42 + t48 * t66
    t17 = -t129 * t41 + t47 * t65
    t16 = -t129 * t40 + t46 * t64
    t15 = -t42 * t66 + t48 * t63
    t14 = -t41 * t65 + t47 * t62
    t13 = -t40 * t64 + t46 * t61
    t12 = (-pkin[1] * t229 + (-pkin[1] * t24 - t45 * t184) * t45) * t220
    t11 = ((-pkin[1] * t23 - t44 * t185) * t44 - pkin[1] * t230) * t221
    t10 = ((-pkin[1] * t22 - t43 * t186) * t43 - pkin[1] * t231) * t222
    t9 = ((pkin[1] * t184 * t235 + t180 * t24 + t182 * t45) * t181 * t45 + (pkin[1] + t184) * t229) * t220
    t8 = ((pkin[1] * t185 * t236 + t180 * t23 + t182 * t44) * t181 * t44 + (pkin[1] + t185) * t230) * t221
    t7 = ((pkin[1] * t186 * t237 + t180 * t22 + t182 * t43) * t181 * t43 + (pkin[1] + t186) * t231) * t222
    t6 = -t66 * t12 - t129 * t9 + (-pkin[0] * t45 ** 2 * t81 + t199) * m[1]
    t5 = -t65 * t11 - t129 * t8 + (-pkin[0] * t44 ** 2 * t80 + t200) * m[1]
    t4 = -t64 * t10 - t129 * t7 + (-pkin[0] * t43 ** 2 * t79 + t201) * m[1]
    t3 = -t63 * t12 - t66 * t9 + ((-rSges[0, 0] * t119 + rSges[0, 1] * t122) * t165 + (rSges[0, 0] * t122 + rSges[0, 1] * t119) * t162) * m[0] + ((t33 * t81 * t235 - t119 * t165 + t122 * t162) * pkin[0] + t199) * m[1]
    t2 = -t62 * t11 - t65 * t8 + ((-rSges[0, 0] * t118 + rSges[0, 1] * t121) * t164 + (rSges[0, 0] * t121 + rSges[0, 1] * t118) * t161) * m[0] + ((t32 * t80 * t236 - t118 * t164 + t121 * t161) * pkin[0] + t200) * m[1]
    t1 = -t61 * t10 - t64 * t7 + ((-rSges[0, 0] * t117 + rSges[0, 1] * t120) * t163 + (rSges[0, 0] * t120 + rSges[0, 1] * t117) * t160) * m[0] + ((t31 * t79 * t237 - t117 * t163 + t120 * t160) * pkin[0] + t201) * m[1]
    t19 = np.array([(-t109 * t157 - t110 * t150 - g[0] + t159) * m[2] + ((t99 * t3 + (-t66 * t209 + t63 * t223) * t190) * t232 + (t97 * t2 + (-t65 * t211 + t62 * t225) * t191) * t233 + (t95 * t1 + (-t64 * t213 + t61 * t227) * t192) * t234 + (-(t6 * t72 + (-t72 * t204 + t66 * t223) * t193) * t232 - (t5 * t71 + (-t71 * t206 + t65 * t225) * t194) * t233 - (t4 * t70 + (-t70 * t208 + t64 * t227) * t195) * t234) * t181) * t183, (-t109 * t150 + t110 * t157 - g[1] + t158) * m[2] + ((t98 * t3 + (-t66 * t210 + t63 * t224) * t190) * t232 + (t96 * t2 + (-t65 * t212 + t62 * t226) * t191) * t233 + (t94 * t1 + (-t64 * t214 + t61 * t228) * t192) * t234 + (-(t6 * t69 + (-t69 * t204 + t66 * t224) * t193) * t232 - (t5 * t68 + (-t68 * t206 + t65 * t226) * t194) * t233 - (t4 * t67 + (-t67 * t208 + t64 * t228) * t195) * t234) * t181) * t183, Icges[2, 2] * t157 + t46 * t1 + t47 * t2 + t48 * t3 - t40 * t4 - t41 * t5 - t42 * t6 + (-t109 * t159 + t110 * t158 + (t170 ** 2 + t171 ** 2) * t157 + (g[0] * t171 + g[1] * t170) * t148 + (g[0] * t170 - g[1] * t171) * t149) * m[2] + ((t15 * t223 - t18 * t209) * t78 + (t15 * t224 - t18 * t210) * t75 + (t14 * t225 - t17 * t211) * t77 + (t14 * t226 - t17 * t212) * t74 + (t13 * t227 - t16 * t213) * t76 + (t13 * t228 - t16 * t214) * t73) * t183])
    tauX = t19
    return tauX


def jacobian_inverse(xP, qJ, pkin, koppelP, legFrame) -> np.ndarray:
    """``Jinv`` (3, 3): row i is leg i's motor rate per platform rate (x, y, phi)."""
    t29 = qJ[0, 0] + qJ[1, 0]
    t15 = sin(t29)
    t18 = cos(t29)
    t40 = 0.1e1 / pkin[0]
    t43 = 0.1e1 / (t15 * cos(qJ[0, 0]) - sin(qJ[0, 0]) * t18) * t40
    t27 = qJ[0, 2] + qJ[1, 2]
    t13 = sin(t27)
    t16 = cos(t27)
    t42 = 0.1e1 / (t13 * cos(qJ[0, 2]) - sin(qJ[0, 2]) * t16) * t40
    t28 = qJ[0, 1] + qJ[1, 1]
    t14 = sin(t28)
    t17 = cos(t28)
    t41 = 0.1e1 / (t14 * cos(qJ[0, 1]) - sin(qJ[0, 1]) * t17) * t40
    t39 = koppelP[0, 0]
    t38 = koppelP[1, 0]
    t37 = koppelP[2, 0]
    t36 = koppelP[0, 1]
    t35 = koppelP[1, 1]
    t34 = koppelP[2, 1]
    t33 = xP[2]
    t32 = legFrame[0, 2]
    t31 = legFrame[1, 2]
    t30 = legFrame[2, 2]
    t26 = cos(t33)
    t25 = sin(t33)
    t24 = cos(t32)
    t23 = cos(t31)
    t22 = cos(t30)
    t21 = sin(t32)
    t20 = sin(t31)
    t19 = sin(t30)
    t12 = -t25 * t36 + t26 * t39
    t11 = -t25 * t35 + t26 * t38
    t10 = -t25 * t34 + t26 * t37
    t9 = t25 * t39 + t26 * t36
    t8 = t25 * t38 + t26 * t35
    t7 = t25 * t37 + t26 * t34
    t1 = np.array([[(-t15 * t21 + t24 * t18) * t43, (t24 * t15 + t21 * t18) * t43, -((-t21 * t12 + t9 * t24) * t18 - t15 * (t12 * t24 + t21 * t9)) * t43], [-(t14 * t20 - t23 * t17) * t41, (t23 * t14 + t20 * t17) * t41, -((-t20 * t11 + t8 * t23) * t17 - t14 * (t11 * t23 + t20 * t8)) * t41], [-(t13 * t19 - t22 * t16) * t42, (t22 * t13 + t19 * t16) * t42, -((-t19 * t10 + t7 * t22) * t16 - t13 * (t10 * t22 + t19 * t7)) * t42]])
    Jinv = t1
    return Jinv
