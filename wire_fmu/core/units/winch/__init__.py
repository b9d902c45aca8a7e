"""The winch (drawworks): drum, band brake, motor and drive train."""
