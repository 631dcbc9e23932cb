"""The one error type of the pipeline: bad input (file, key, what was expected). The launcher turns
it into a one-line message and exit code 2."""


class PatientInputError(Exception):
    pass
