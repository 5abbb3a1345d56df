"""The models the guidance tests share: Nadkarni's two configurations and the PUMA 560."""

import kinestat

C1 = kinestat.load("nadkarni-config1")
C2 = kinestat.load("nadkarni-config2")
PUMA = kinestat.load("puma560")
