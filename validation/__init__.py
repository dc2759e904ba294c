"""FE-vs-theory comparisons, verification studies, plots and reports."""


def paper_model(**mesh):
    """The shipped paper model, with the mesh fields given (``size``, ``size_3d``; None: the
    model's own) replaced."""
    import dataclasses

    from gatetherm.frame.config import load_config

    cfg = load_config()
    mesh = {k: v for k, v in mesh.items() if v}
    if not mesh:
        return cfg
    return dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, mesh=dataclasses.replace(cfg.model.mesh,
                                                                                                   **mesh)))
