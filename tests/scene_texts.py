"""Small scene texts shared by the scene, runner and CLI tests."""

# a 3 m x 3 m horizontal radial fracture on 1 m elements, dense, two steps
RADIAL_3D_BODY = """
[material]
shear_modulus = 24e9
poisson_ratio = 0.25
[fluid]
viscosity = 1e-3
compressibility = 4.4e-10
[stress]
s_hmin = 10e6
s_hmax = 12e6
s_v = 8e6
[[cluster]]
position = [0.0, 0.0, 0.0]
rate = 0.01
wellbore_volume = 0.005
[[initial_fracture]]
center = [0.0, 0.0, 0.0]
e1 = [1.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
length = 3.0
height = 3.0
element_size = 1.0
[propagation]
toughness = 5e6
[numerics]
end_time = 2.0
backend = "dense"
initial_pressure = 10e6
[reference]
kind = "radial-k"
"""
