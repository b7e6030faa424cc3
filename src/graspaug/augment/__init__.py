"""The paper's method, Section III of *Improving Robotic Grasping Ability Through Deep Shape Generation*, in order.

- :mod:`~graspaug.augment.corpus`: the corpus made usable: each file one closed solid, scaled, split (III-A's data);
- :mod:`~graspaug.augment.scores`: rarity (eqs. (3)-(4), on the AE-Critic latents) and graspness (the share of
  robust antipodal grasps); :mod:`~graspaug.augment.score_tables`: the tables, histograms and summaries of both;
- :mod:`~graspaug.augment.embedding`: the 2-D t-SNE map of the latents (Fig. 1);
- :mod:`~graspaug.augment.candidates`: base sets, pairs of rare / graspable neighbours, the α schedule and the
  candidate streams of every pool (targeted, random, recon, failure), and the pool tables (III-C);
- :mod:`~graspaug.augment.pools`: the pools decoded and meshed (decode → fill → open → marching cubes → smooth),
  the blend pool with no network, and the failure-anchored shapes of the lifelong loop.

The AutoEncoder-Critic itself (III-B) is :mod:`graspaug.nets.ae_critic` with its training loop in
:mod:`graspaug.training.autoencoder`; the decoded grid becomes a mesh in :mod:`graspaug.geometry.from_voxels`.
"""
