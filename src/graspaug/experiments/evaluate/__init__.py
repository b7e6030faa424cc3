"""``graspaug evaluate``: trained GQ-CNNs tested on any folder of meshes (a user's own objects).

``testset.py`` turns the folder into a rendered, labelled test set (ingested at real size, grasps sampled and labelled,
datapoints rendered for the models' camera) cached by its content; ``numbers.py`` each model's test AP and the paired
difference of each against the first, over one bootstrap of the objects; ``words.py`` the report.
"""
