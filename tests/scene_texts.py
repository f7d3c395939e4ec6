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
time_step = 1.0
end_time = 2.0
backend = "dense"
initial_pressure = 10e6
[reference]
kind = "radial-k"
"""

# a 0.75 m plane-strain crack on 0.25 m elements, toughness dominated; ends inside
# [numerics], so the caller appends end_time and what follows
KGD_2D_HEAD = """
dimension = 2
[material]
shear_modulus = 10e9
poisson_ratio = 0.25
[fluid]
viscosity = 1e-4
compressibility = 4.5e-10
[stress]
s_hmin = 0.5e6
s_hmax = 1e6
[[cluster]]
position = [0.0, 0.0]
rate = 5e-4
wellbore_volume = 0.01
[[initial_fracture]]
shape = "line"
p0 = [-0.375, 0.0]
p1 = [0.375, 0.0]
element_size = 0.25
[propagation]
toughness = 5e6
[numerics]
time_step = 1.0
"""
