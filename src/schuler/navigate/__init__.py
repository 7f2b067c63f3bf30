"""The nonlinear INS on WGS-84: truth, strapdown and platform mechanizations, and the seeds' referee.
"""
