N_MU = 2
N_R = 2
VALUES = (1.0, 1.0, 1.0, 1.0)
