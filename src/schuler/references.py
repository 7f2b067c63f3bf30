"""The bibliography: every document the toolkit follows, cited by author, title, venue and year.

Each system names its source here; docstrings, ``--help``, reproduction tables
and the report cite these entries, and an equation number always says which
document it belongs to ("Drozdovich (1959), eq. (29)").

Examples
--------
>>> print(DROZDOVICH_1959.citation)
Drozdovich, V. N., "On an inertial method of measuring velocities", Izvestiya VUZ, Priborostroyeniye,
no. 3, pp. 29-39, 1959
>>> DROZDOVICH_1959.short
'Drozdovich (1959)'
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Reference:
    """One document.

    Attributes
    ----------
    key : str
        Short name used in the code (``"drozdovich1959"``).
    authors : str
        As printed (``"Drozdovich, V. N."``).
    title, venue : str
    year : str
        Year of publication ("n.d." where the document prints none).
    pages, doi, note : str
        Pages, DOI, and anything else a reader needs to find it.
    """

    key: str
    authors: str
    title: str
    venue: str
    year: str
    pages: str = ""
    doi: str = ""
    note: str = ""

    @property
    def citation(self) -> str:
        parts = [self.authors, f'"{self.title}"', self.venue]
        if self.pages:
            parts.append(self.pages)
        parts.append(self.year)
        text = ", ".join(p for p in parts if p)
        if self.doi:
            text += f", doi:{self.doi}"
        return text

    @property
    def short(self) -> str:
        """Author-year form for tables: ``Drozdovich (1959)``."""
        first = self.authors.split(",")[0].strip()
        many = self.authors.count(";") > 0 or " and " in self.authors
        return f"{first}{' et al.' if many else ''} ({self.year})"


BOLLAY_1966 = Reference(
    "bollay1966", "Bollay, W.",
    "A Critical Meeting on the Development of Inertial Navigation - Related to \"The Story of 84 Minutes\"",
    "Engineering Case Library, Stanford University (supplement to J. P. Den Hartog's Case No. 1001)", "1966",
    note="Problems 1-3 and the hover problem")
DROZDOVICH_1959 = Reference(
    "drozdovich1959", "Drozdovich, V. N.", "On an inertial method of measuring velocities",
    "Izvestiya VUZ, Priborostroyeniye, no. 3", "1959", pages="pp. 29-39",
    note="English translation JPRS 2912, US Joint Publications Research Service, 1960")
PULSE_CALIBRATION = Reference(
    "pulsecalibration", "(authors not legible in the available copy)",
    "Measuring the drift rate of gyroscopic devices by alternating-sign controlled precession",
    "Russian journal, section \"Informatika, vychislitel'naya tekhnika i upravlenie\"", "n.d.",
    note="known only from an OCR-damaged copy; equation numbers (2)-(16) are the article's")
KPI_LAB_MANUAL = Reference(
    "meleshko", "Meleshko, V. V. (compiler)",
    "Physical gyrocompassing of a semi-analytic INS (laboratory manual, course \"Navigation devices and systems\")",
    "National Technical University of Ukraine \"Kyiv Polytechnic Institute\", Department of Orientation and "
    "Navigation Devices and Systems", "n.d.", note="equations (1.1)-(1.25)")
FEDOROV_2020 = Reference(
    "fedorov2020", "Fedorov, V. N.; Kikot, V. V.; Shtefan, N. I.",
    "Determination of meridian position by a two-step ground gyrocompass during natural run-down of its rotor",
    "Mechanics of Gyroscopic Systems, no. 40", "2020", doi="10.20535/0203-3771402020249107")

GROVES_2013 = Reference(
    "groves2013", "Groves, P. D.",
    "Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems, 2nd ed.",
    "Artech House, Boston", "2013")
TITTERTON_2004 = Reference(
    "titterton2004", "Titterton, D. H.; Weston, J. L.", "Strapdown Inertial Navigation Technology, 2nd ed.",
    "IET, Stevenage", "2004")
SAVAGE_2000 = Reference("savage2000", "Savage, P. G.", "Strapdown Analytics", "Strapdown Associates, Maple Plain MN",
                        "2000")
BRITTING_1971 = Reference("britting1971", "Britting, K. R.", "Inertial Navigation Systems Analysis",
                          "Wiley-Interscience, New York", "1971")
BENSON_1975 = Reference(
    "benson1975", "Benson, D. O.",
    "A comparison of two approaches to pure-inertial and Doppler-inertial error analysis",
    "IEEE Transactions on Aerospace and Electronic Systems, vol. AES-11, no. 4", "1975", pages="pp. 447-455")
IEEE_952 = Reference(
    "ieee952", "IEEE",
    "IEEE Standard Specification Format Guide and Test Procedure for Single-Axis Interferometric Fiber Optic "
    "Gyros (IEEE Std 952-1997), Annex C: Allan variance", "IEEE, New York", "1998")
EL_SHEIMY_2008 = Reference(
    "elsheimy2008", "El-Sheimy, N.; Hou, H.; Niu, X.",
    "Analysis and modeling of inertial sensors using Allan variance",
    "IEEE Transactions on Instrumentation and Measurement, vol. 57, no. 1", "2008", pages="pp. 140-149")
TEDALDI_2014 = Reference(
    "tedaldi2014", "Tedaldi, D.; Pretto, A.; Menegatti, E.",
    "A robust and easy to implement method for IMU calibration without external equipments",
    "IEEE International Conference on Robotics and Automation (ICRA)", "2014", pages="pp. 3042-3049")
PRIKHODKO_2013 = Reference(
    "prikhodko2013", "Prikhodko, I. P.; Zotov, S. A.; Trusov, A. A.; Shkel, A. M.",
    "What is MEMS gyrocompassing? Comparative analysis of maytagging and carouseling",
    "Journal of Microelectromechanical Systems, vol. 22, no. 6", "2013", pages="pp. 1257-1266")

BIBLIOGRAPHY: tuple[Reference, ...] = (
    BOLLAY_1966, DROZDOVICH_1959, PULSE_CALIBRATION, KPI_LAB_MANUAL, FEDOROV_2020, GROVES_2013, TITTERTON_2004,
    SAVAGE_2000, BRITTING_1971, BENSON_1975, IEEE_952, EL_SHEIMY_2008, TEDALDI_2014, PRIKHODKO_2013,
)
"""Every document cited, sources of the five seed systems first."""
