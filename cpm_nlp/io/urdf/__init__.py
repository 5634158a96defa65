"""The pieces of the URDF import (`cpm_nlp.io.import_urdf`): reading the URDF and its
Extended URDF sidecar, assembling the loops, the graph of bodies and joints and its
simplification, and the mechanism file written."""
