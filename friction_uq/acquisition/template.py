"""The SETUP.toml that ``friction-uq import --template`` prints: the paper's set-up, every key explained."""

TEMPLATE = '''\
# SETUP.toml: how friction-uq import reads your oscilloscope files into a test record (test.h5).
# Values below are the set-up of Durand et al. 2016; replace them with your own.
# All quantities in SI units: m, s, Pa, m/s, kg/m^3, Hz, V.
# Use: friction-uq import scope.csv --setup SETUP.toml -o A-07.h5

[record]
test_id = "A-07"                 # unique within its campaign
campaign = "A"                   # the series of tests it belongs to
date = "2016-03-01"              # optional, ISO 8601
description = "I1 in steel tube, PTFE on both faces"   # optional
striker_velocity = 10.0          # optional, m/s, from the light gates; lets the import check the input gauge

[time]
# Either the time column of the files (seconds unless units says otherwise) ...
column = "Time"                  # its header name, or its 1-based number: column = 1
# units = "s"                    # "s", "ms", "us" or "ns"
# ... or a sample rate and the time of the first sample (for files without a time column):
# sample_rate = 5e6              # Hz
# t0 = -1e-4                     # s
# Leave [time] out for TDMS, LeCroy, Tektronix and Rigol files: they carry their own time base.

# ---- the gauges ---------------------------------------------------------------------------------
# column: the header name in the file, its 1-based number, or for TDMS "group/channel".
# file:   which file holds it, when you give one file per channel (its name as given on the
#         command line); leave it out when one file holds every channel.
# units:  "V", "mV", "strain" or "microstrain" (as the file holds the numbers).
# For V and mV, either strain_per_volt (strain per volt at the scope input) or:
#   gauge_factor, bridge ("quarter", "half", "full" or the bridge factor as a number),
#   excitation (bridge supply, V) and amplifier_gain (default 1); then
#   strain_per_volt = 4 / (bridge factor x gauge_factor x excitation x amplifier_gain).
# sign:   +1 when the file's positive is elongation (a compressive bar wave reads negative),
#         -1 when it is the other way round (a bridge wired to read compression positive).

[channels.input_bar]             # axial gauge on the input bar: incident then reflected wave
column = "CH1"
units = "V"
gauge_factor = 2.1
bridge = "half"                  # two axial gauges on opposite sides (bending cancels)
excitation = 10.0                # V
amplifier_gain = 100.0
sign = 1

[channels.internal_output_bar]   # axial gauge on the internal (solid) output bar
column = "CH2"
units = "V"
strain_per_volt = 2.0e-4
sign = 1

[channels.external_output_bar]   # axial gauge on the outer surface of the external (hollow) output bar
column = "CH3"
units = "V"
strain_per_volt = 2.0e-4
sign = 1

[channels.tube_hoop]             # optional: circumferential gauge on the confinement tube
column = "CH4"
units = "V"
strain_per_volt = 5.0e-5
sign = 1                         # +1: the tube swelling reads positive

# ---- the apparatus (the record contract's names; docs/record-format.md) ----------------------------
[apparatus.striker]
young_modulus = 166e9            # Pa
wave_speed = 4555.0              # m/s
diameter = 0.020                 # m
length = 1.05                    # m

[apparatus.input_bar]
young_modulus = 166e9
wave_speed = 4555.0
diameter = 0.020
length = 2.5
gauge_distance = 1.22            # m, from the end that touches the plug
# poisson_ratio = 0.29           # optional on every bar: only the dispersion correction uses it

[apparatus.internal_output_bar]
young_modulus = 72.8e9
wave_speed = 5092.0
diameter = 0.010
length = 1.46
gauge_distance = 0.33            # m, from the end that touches the sample

[apparatus.external_output_bar]
young_modulus = 205e9
wave_speed = 5162.0
outer_diameter = 0.040
inner_diameter = 0.030
length = 1.5
gauge_distance = 0.295           # m, from the end that touches the tube

[apparatus.tube]
young_modulus = 200e9
poisson_ratio = 0.29
inner_diameter = 0.010
outer_diameter = 0.024
length = 0.040
gauge_offset = 0.0025            # m, from the sample's middle to the hoop gauge's middle at the start,
                                 # positive towards the output bars
gauge_width = 0.002              # m, the hoop gauge grid's width along the tube axis

[apparatus.sample]
material = "I1"                  # names the prior file of nu (friction-uq priors lists them)
diameter = 0.010
length = 0.010
young_modulus = 2e9
density = 1850.0

# [apparatus.plug]               # optional
# length = 0.010
# young_modulus = 200e9
# density = 7800.0
'''
