"""Planar floating-frame flexible bodies from reduced (Craig-Bampton) files: the body, its quasi-static start, its modal damping and step bound."""
