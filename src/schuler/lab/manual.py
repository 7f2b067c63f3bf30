"""The KPI lab manual's tasks and control questions, in English, with where the lab answers them.

Source: Meleshko, KPI lab manual of physical gyrocompassing
(:data:`schuler.references.KPI_LAB_MANUAL`), Sec. 3 "Tasks" and Sec. 4
"Control questions" (translated from Russian). Task 4 (the "MIS-2" system) is
left out: the manual does not give that system's parameters.
"""

from __future__ import annotations

TASK_TITLES = {
    1: "Accuracy and time of gyrocompassing",
    2: "The simplified model (1.19) beside it",
    3: "The same cases in mu, nu",
    5: "Phase trajectory in the (delta, beta) plane",
}

TASK_TEXT = {
    1: "Study gyrocompassing (determine its accuracy and time) from the solutions of system (1.15), varying "
       "phi; the residual drifts Delta omega_dx, Delta omega_dy, Delta omega_dz; the gains c_a, c_Gamma; the "
       "latitude error Delta phi; the accelerometer errors Delta a_x, Delta a_y; and the azimuth A. Observe the "
       "constraints delta < 0.4, beta < 0.01 (rad) and a largest azimuth slew rate delta' = 0.2 rad/s.",
    2: "Compare the results with those of the simulation by the simplified model (1.19).",
    3: "For the same cases, study the motion of the platform in the coordinates mu, nu (system (1.12); here its "
       "corrected form (1.17)).",
    5: "Plot the phase trajectory of the platform's motion in the plane of the parameters delta and beta.",
}

QUESTIONS = {
    1: "What do a gyrocompass and an inertial platform in physical gyrocompassing have in common?",
    2: "How does a gyrocompass with indirect control differ from an inertial platform in gyrocompassing?",
    3: "How do the platform's stabilisation motors take part in gyrocompassing?",
    4: "In which azimuth positions can the platform settle?",
    5: "What happens if only one of the platform's two accelerometers is used?",
    6: "How does the gyrocompassing scheme of the lab differ from the one of the lectures?",
    7: "What does the accuracy of gyrocompassing depend on?",
    8: "What does the time of gyrocompassing depend on?",
    9: "Under which restrictions are the equations of motion used valid?",
    10: "Compare the results of the simulation with the analytic estimates.",
    11: "Why do the equations use two pairs of angles for the platform's deviation from the horizontal plane?",
    12: "Where do the gyro drift components fed into the control scheme come from?",
    13: "How does the accuracy of the accelerometers affect the error and the time of gyrocompassing?",
    14: "Over which range does the rate of azimuth correction change (rad/s)?",
}

HINTS = {
    4: "Watch where the trajectory ends for different azimuths A and initial errors: the steady point (star).",
    7: "Sweep each parameter: the azimuth error follows (1.21), delta_y = c_Gamma/(c_a U cos phi) Delta omega_dz "
       "- (c_Gamma/c_a) Delta phi + Delta omega_dxi/(U cos phi).",
    8: "Sweep c_a and c_Gamma: the settling time is 5/h with h = c_Gamma/2 (oscillatory loop).",
    9: "Small angles (the constraints below), tilts of a few arcminutes after levelling, gains much larger than "
       "the Earth rate; the page marks every case that breaks a constraint.",
    10: "Simulated points and the analytic curves are drawn together; the table gives both numbers.",
    11: "mu, nu are the platform's tilts about its own axes, beta, alpha about the geographic ones: compare them.",
    13: "Sweep Delta a_x or Delta a_y: the azimuth error of (1.19) does not move, beta_y does (1.25); "
        "the full model shifts by arcseconds.",
    14: "The largest |delta'| of each case is drawn against its limit 0.2 rad/s.",
}

TASK_QUESTIONS = {1: (7, 8, 9, 13, 14), 2: (9, 10), 3: (11, 5), 5: (4, 8)}
"""Which control questions each task page helps to answer."""
