"""graspaug: improve learned grasp planners by generating training shapes where data is thin."""

__version__ = "0.1.0"
