"""Spatial parallel robots: Stewart–Gough hexapods (UPS, RUS, PUS) and Deltas (RSS2, PSS2).

The same method as the planar robots (:mod:`rpr3gen_derive.planar`), in three dimensions: each
leg's kinematics from the platform pose, then the joint loads by the principle of virtual work
(docs/spatial-robots.md). Written in the engine's terms (:mod:`rpr3gen_derive.codegen`).
"""
