"""The [well] of a scene and the perforations of its clusters (issue 35,
:mod:`hmatddm.flow.well`): which cluster takes which perforations, and the cross-key checks
that name the field (a cluster's ``rate`` without a well, none with one; perforation count
and diameter together; clusters on the well; the pump schedule's times increasing)."""
from ..errors import InputError


PERFORATION_KEYS = ("perforations", "perforation_diameter", "discharge_coefficient")


def perforations(scene, index):
    """The perforation keys of ``cluster[index]``: its own, else the [well]'s (defaults for
    every cluster)."""
    cluster, well = scene["cluster"][index], scene.get("well", {})
    own = {key: cluster[key] for key in PERFORATION_KEYS if key in cluster}
    if own:
        return own
    return {key: well[key] for key in PERFORATION_KEYS if key in well}


def check_clusters_and_well(scene):
    """Without a [well] every cluster has its ``rate``; with one (issue 35,
    :mod:`hmatddm.flow.well`) none has, each has its perforations (count and diameter, both or
    neither; its own or the well's), lies on the well, and the pump schedule's times increase."""
    clusters = scene["cluster"]
    well = scene.get("well", {})
    given = [key for key in ("perforations", "perforation_diameter") if key in well]
    if len(given) == 1:
        other = "perforation_diameter" if given[0] == "perforations" else "perforations"
        raise InputError(f"well.{other} is required with well.{given[0]} (the count and the diameter of the "
                         "perforations of every cluster that gives none)")
    if "discharge_coefficient" in well and not given:
        raise InputError("well.discharge_coefficient needs well.perforations and well.perforation_diameter")
    for i, cluster in enumerate(clusters):
        given = [key for key in ("perforations", "perforation_diameter") if key in cluster]
        if len(given) == 1:
            other = "perforation_diameter" if given[0] == "perforations" else "perforations"
            raise InputError(f"cluster[{i}].{other} is required with cluster[{i}].{given[0]} (the count and the "
                             "diameter of the cluster's perforations)")
        if "discharge_coefficient" in cluster and not given:
            raise InputError(f"cluster[{i}].discharge_coefficient needs cluster[{i}].perforations and "
                             f"cluster[{i}].perforation_diameter (the orifices it describes)")
        if given and "well" not in scene:
            raise InputError(f"cluster[{i}].{given[0]} needs a [well]: perforation friction splits a shared pump's "
                             "rate (without a [well] each cluster injects its own rate)")
    if "well" not in scene:
        for i, cluster in enumerate(clusters):
            if "rate" not in cluster:
                raise InputError(f"cluster[{i}].rate (m^3/s) is required (or a [well] whose pump schedule the "
                                 "clusters share)")
        return
    from ..flow.fluid import Cluster
    from ..flow.well import PumpRate, Well

    section = scene["well"]
    for i, cluster in enumerate(clusters):
        if "rate" in cluster:
            raise InputError(f"cluster[{i}].rate must be left out with a [well]: the pump schedule well.schedule sets "
                             "the rates, which the perforations split")
    schedule = PumpRate.from_rows(section["schedule"], section["interpolation"])
    well = Well(schedule, tuple(section["heel"]), tuple(section["direction"]), volume=section["volume"],
                diameter=section.get("diameter"), friction_factor=section["friction_factor"])
    well.system([Cluster(tuple(c["position"]), wellbore_volume=c["wellbore_volume"], **perforations(scene, i))
                 for i, c in enumerate(clusters)], scene["fluid"]["density"])
