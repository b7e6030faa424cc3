"""The DVC pipeline and the ``graspaug`` command: ``params`` (params.yaml's model, its sections and profiles),
``stages`` (one thin adapter per stage), ``paths`` (the only module that knows file names) and ``cli``.
Nothing below this package imports it."""
