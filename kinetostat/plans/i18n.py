"""The message catalogue of the sheets, the worksheet, the answer keys and their index: every word
they print, in English, Ukrainian and Russian (the seeds are Ukrainian and Russian), and the
numbers and units as each language writes them (decimal comma in uk and ru, Н·м, рад/с²).

    >>> from kinetostat.plans.i18n import num, text, unit
    >>> num(3185.2, "uk"), num(2.852e-17, "en"), unit("N m", "ru"), text("scale", "uk")
    ('3185', '0', 'Н·м', 'масштаб')

`MESSAGES[key] = (en, uk, ru)`; `text(key, lang, **fields)` formats one. `PHRASES` translates the
generated English notes of the plans (branches, positions) phrase by phrase; `words_en()` is the
English side the tests look for in uk and ru output.

May use: the standard library, numpy and `kinetostat.structure` (the kinds of the dyads).
"""
from __future__ import annotations

import math
import re

import numpy as np

from ..structure import GROUP_KINDS

__all__ = ["LANGS", "MESSAGES", "PHRASES", "UNITS", "check_lang", "text", "plural", "PLURALS", "num", "unit", "phrase",
           "words_en", "accuracy", "group_name", "ZERO"]

LANGS = ("en", "uk", "ru")
#: A magnitude below this (SI) is printed as 0: the solver's rounding noise, never a value.
ZERO = 1e-9

MESSAGES: dict[str, tuple[str, str, str]] = {
    # plan titles
    "plan.positions": ("Plan of positions", "План положень", "План положений"),
    "plan.velocity": ("Velocity plan", "План швидкостей", "План скоростей"),
    "plan.acceleration": ("Acceleration plan", "План прискорень", "План ускорений"),
    "plan.group": ("Plan of group", "План групи", "План группы"),
    "plan.forces": ("Force plan of group", "План сил групи", "План сил группы"),
    "plan.crank": ("Plan of the initial link", "План початкової ланки", "План начального звена"),
    "plan.lever": ("Zhukovsky's lever", "Важіль Жуковського", "Рычаг Жуковского"),
    "plan.mechanism": ("Mechanism", "Механізм", "Механизм"),      # at any angle: "φ = …" follows
    # title block and notes
    "angle": ("crank angle", "кут кривошипа", "угол кривошипа"),
    "scale": ("scale", "масштаб", "масштаб"),
    "scales": ("scales", "масштаби", "масштабы"),
    "forces at": ("forces at", "сили в масштабі", "силы в масштабе"),
    "sheet": ("sheet A3, true to scale in mm", "аркуш А3, креслення в мм у масштабі",
              "лист А3, чертёж в мм в масштабе"),
    "segment": ("segment", "відрізок", "отрезок"),
    "results": ("Results", "Результати", "Результаты"),
    "equation": ("Vector equation, in the order drawn", "Векторне рівняння в порядку побудови",
                 "Векторное уравнение в порядке построения"),
    "nofit": ("the plan does not fit the sheet at this scale", "план не вміщується на аркуші в цьому масштабі",
              "план не помещается на листе в этом масштабе"),
    "out of scale": ("drawn out of scale ({length} mm at the scale)", "показано поза масштабом ({length} мм у масштабі)",
                     "показано вне масштаба ({length} мм в масштабе)"),
    "negligible": ("negligible: {length} mm at the scale, not laid off",
                   "нехтовно мала: {length} мм у масштабі, не відкладається",
                   "пренебрежимо мала: {length} мм в масштабе, не откладывается"),
    "arms natural": ("arms h measured on the drawing, mm", "плечі h виміряно на кресленні, мм",
                     "плечи h измерены на чертеже, мм"),
    "lever turned": ("the velocity plan is not turned: every force is turned by 90° clockwise and carried to the "
                     "like point of the plan; arms h are dimension lines from the pole p to the forces' lines",
                     "план швидкостей не повернуто: кожну силу повернуто на 90° за годинниковою стрілкою й "
                     "перенесено в однойменну точку плану; плечі h — розмірні лінії від полюса p до ліній дії сил",
                     "план скоростей не повёрнут: каждая сила повёрнута на 90° по часовой стрелке и перенесена в "
                     "одноимённую точку плана; плечи h — размерные линии от полюса p до линий действия сил"),
    "within 5": ("within the texts' 5 %", "у межах допустимих 5 %", "в пределах допустимых 5 %"),
    "beyond 5": ("beyond the texts' 5 %", "перевищує допустимі 5 %", "превышает допустимые 5 %"),
    "by force plans": ("by the force plans", "за планами сил", "по планам сил"),
    "by lever": ("by Zhukovsky's lever", "за важелем Жуковського", "по рычагу Жуковского"),
    "couple": ("couple of forces at the ends of the link", "пара сил на кінцях ланки", "пара сил на концах звена"),
    "pole": ("pole", "полюс", "полюс"),
    "M = sum": ("sum of the moments about the crank's axis is zero", "з рівняння моментів відносно осі кривошипа",
                "из уравнения моментов относительно оси кривошипа"),
    "M = F r_b": ("balancing force times the base radius", "зрівноважувальна сила на радіус основного кола",
                  "уравновешивающая сила на радиус основной окружности"),
    "legend.positions": ("bold: the design position; thin: positions 0-11 every 30°; curves: paths of the centres "
                         "of mass", "жирно: розрахункове положення; тонко: положення 0-11 через 30°; криві: "
                         "траєкторії центрів мас", "жирно: расчётное положение; тонко: положения 0-11 через 30°; "
                         "кривые: траектории центров масс"),
    "legend.velocity": ("p: pole; vectors p-x: absolute velocities; the others: relative velocities",
                        "p: полюс; вектори p-x: абсолютні швидкості; інші: відносні швидкості",
                        "p: полюс; векторы p-x: абсолютные скорости; остальные: относительные скорости"),
    "legend.acceleration": ("π: pole; n: normal, n-x: tangential, k: Coriolis, k-x: relative parts",
                            "π: полюс; n: нормальні, n-x: дотичні, k: коріолісові, k-x: відносні складові",
                            "π: полюс; n: нормальные, n-x: касательные, k: кориолисовы, k-x: относительные "
                            "составляющие"),
    "legend.mechanism": ("ω: angular velocity, ε: angular acceleration (senses); S: centres of mass",
                         "ω: кутова швидкість, ε: кутове прискорення (напрямки); S: центри мас",
                         "ω: угловая скорость, ε: угловое ускорение (направления); S: центры масс"),
    "guide": ("guide {pair}", "напрямна {pair}", "направляющая {pair}"),      # of the sliding pair: its links
    "legend.lines": ("line widths, mm:", "товщина ліній, мм:", "толщина линий, мм:"),
    "role.result": ("result", "результат", "результат"),
    "role.link": ("link", "ланка", "звено"),
    "role.given": ("given", "задана", "заданная"),
    "role.component": ("component", "складова", "составляющая"),
    "role.construction": ("construction", "побудова", "построение"),
    "role.auxiliary": ("auxiliary", "допоміжна", "вспомогательная"),
    "slot": ("slot of link {k} ({P})", "паз ланки {k} ({P})", "паз звена {k} ({P})"),
    "construction.line": ("line of {name} through {P}", "лінія {name} через {P}", "линия {name} через {P}"),
    "construction.point": ("{P}: the intersection of the lines", "{P}: перетин ліній", "{P}: пересечение линий"),
    "coriolis": ("Cor", "к", "к"),          # the superscript of the Coriolis acceleration: a^Cor, a^к
    "line of action": ("line of action", "лінія зачеплення", "линия зацепления"),
    "pitch circle of the wheel": ("pitch circle of the wheel", "початкове коло колеса",
                                  "начальная окружность колеса"),
    "pitch circle of the pinion": ("pitch circle of the pinion", "початкове коло шестерні",
                                   "начальная окружность шестерни"),
    "mm": ("mm", "мм", "мм"),
    "group.kind": ("group {links} (class {klass}, kind {n})", "група {links} ({klass}-го класу {n}-го виду)",
                   "группа {links} ({klass}-го класса {n}-го вида)"),
    "group.class": ("group {links} (class {klass})", "група {links} ({klass}-го класу)", "группа {links} ({klass}-го класса)"),
    "group.kinds_12": ("of class 2, kinds 1 (RRR) and 2 (RRP)", "2-го класу 1-го і 2-го виду", "2-го класса 1-го и 2-го вида"),
    # the index of the answer keys
    "ix.title": ("Logvinenko, Nadtoka 2021: answer keys of the task variants", "Логвіненко, Надтока 2021: відповіді до варіантів завдань",
                 "Логвиненко, Надтока 2021: ответы к вариантам заданий"),
    "ix.intro": ("Each folder holds the variant's model (`task<T>_<CODE>.toml`, its header states the table's "
                 "columns and every assumption), its worksheet (`worksheet.md`, `.html`, `.csv`, `.json`) and its "
                 "plans (`SVG` sheets, `segments.csv`) at the design position φ1. R(i,j) is the force of link i on "
                 "link j; {M} the moment the drive applies to the crank (about +z, N·m).",
                 "Кожна тека містить модель варіанта (`task<T>_<CODE>.toml`, у заголовку — стовпці таблиці та всі "
                 "припущення), розрахунковий лист (`worksheet.md`, `.html`, `.csv`, `.json`) і плани (аркуші `SVG`, "
                 "`segments.csv`) у розрахунковому положенні φ1. R(i,j) — сила дії ланки i на ланку j; {M} — "
                 "момент, який привод прикладає до кривошипа (відносно осі +z, Н·м).",
                 "Каждая папка содержит модель варианта (`task<T>_<CODE>.toml`, в заголовке — столбцы таблицы и все "
                 "допущения), расчётный лист (`worksheet.md`, `.html`, `.csv`, `.json`) и планы (листы `SVG`, "
                 "`segments.csv`) в расчётном положении φ1. R(i,j) — сила действия звена i на звено j; {M} — "
                 "момент, который привод прикладывает к кривошипу (относительно оси +z, Н·м)."),
    "ix.task": ("Task {task}: {title} (table {table})", "Завдання {task}: {title} (таблиця {table})",
                "Задача {task}: {title} (таблица {table})"),
    "ix.code": ("code", "код", "код"),
    "ix.at": ("at φ1", "при φ1", "при φ1"),
    "ix.largest": ("largest reaction at φ1", "найбільша реакція при φ1", "наибольшая реакция при φ1"),
    "ix.cycle": ("max over the cycle", "найбільше за цикл", "наибольшее за цикл"),
    # the command line
    "cli.plans": ("{name} at φ = {phi}° ({scales}): {n} files -> {out}", "{name}, φ = {phi}° ({scales}): {n} файлів -> {out}",
                  "{name}, φ = {phi}° ({scales}): {n} файлов -> {out}"),
    "cli.all": ("Answer keys: {keys} (tasks {tasks}) -> {out}/`task<T>_<CODE>`/; index -> {index}; {s} s",
                "Ключі відповідей: {keys} (завдання {tasks}) -> {out}/`task<T>_<CODE>`/; зміст -> {index}; {s} с",
                "Ключи ответов: {keys} (задания {tasks}) -> {out}/`task<T>_<CODE>`/; оглавление -> {index}; {s} с"),
    "cli.variant": ("Logvinenko, Nadtoka 2021, task {task} ({title}), variant {code}: table {table} columns",
                    "Логвіненко, Надтока 2021, задача {task} ({title}), варіант {code}: стовпці таблиці {table}",
                    "Логвиненко, Надтока 2021, задача {task} ({title}), вариант {code}: столбцы таблицы {table}"),
    "cli.at": ("at φ1 = {phi}°: {M} = {M_value}, largest reaction |{R}| = {R_value}",
               "при φ1 = {phi}°: {M} = {M_value}, найбільша реакція |{R}| = {R_value}",
               "при φ1 = {phi}°: {M} = {M_value}, наибольшая реакция |{R}| = {R_value}"),
    "cli.cycle": ("over the cycle: max |{M}| = {M_value}, max |R| = {R_value}",
                  "за цикл: найбільше |{M}| = {M_value}, найбільше |R| = {R_value}",
                  "за цикл: наибольшее |{M}| = {M_value}, наибольшее |R| = {R_value}"),
    "cli.files_keys": ("model {model} (assumptions in its header), worksheet and plans at the text's rule of scales "
                       "(no teacher's pack: its one-sheet scales may differ), `cycle.csv`: {n} files -> {out}",
                       "модель {model} (припущення в її заголовку), розрахунковий лист і плани в масштабах за правилом "
                       "посібника (без пакета викладача: його масштаби одного аркуша можуть відрізнятися), `cycle.csv`: "
                       "{n} файлів -> {out}",
                       "модель {model} (допущения в её заголовке), расчётный лист и планы в масштабах по правилу "
                       "пособия (без пакета преподавателя: его масштабы одного листа могут отличаться), `cycle.csv`: "
                       "{n} файлов -> {out}"),
    "cli.files": ("model {model} (assumptions in its header), worksheet, plans, `cycle.csv`, the student's sheet "
                  "`sheet.pdf`, the answer key `key.pdf` and the A3 sheet `plans_a3.pdf`: {n} files -> {out}",
                  "модель {model} (припущення в її заголовку), розрахунковий лист, плани, `cycle.csv`, аркуш "
                  "завдання `sheet.pdf`, ключ відповідей `key.pdf` і аркуш А3 `plans_a3.pdf`: {n} файлів -> {out}",
                  "модель {model} (допущения в её заголовке), расчётный лист, планы, `cycle.csv`, лист задания "
                  "`sheet.pdf`, ключ ответов `key.pdf` и лист А3 `plans_a3.pdf`: {n} файлов -> {out}"),
    # the worksheet
    "ws.title": ("Worksheet: {name}, φ = {phi}°", "Розрахунковий лист: {name}, φ = {phi}°",
                 "Расчётный лист: {name}, φ = {phi}°"),
    "ws.kinematics": ("Kinematics: velocities", "Кінематика: швидкості", "Кинематика: скорости"),
    "ws.accelerations": ("Kinematics: accelerations", "Кінематика: прискорення", "Кинематика: ускорения"),
    "ws.inertia": ("Inertia forces and loads", "Сили інерції та навантаження", "Силы инерции и нагрузки"),
    "ws.reactions": ("Reactions in the kinematic pairs", "Реакції в кінематичних парах",
                     "Реакции в кинематических парах"),
    "ws.crank": ("The initial link and Zhukovsky's lever", "Початкова ланка і важіль Жуковського",
                 "Начальное звено и рычаг Жуковского"),
    "ws.friction": ("Friction in the reactions", "Тертя в реакціях", "Трение в реакциях"),
    "ws.cw": ("clockwise", "за годинниковою стрілкою", "по часовой стрелке"),
    "ws.ccw": ("counter-clockwise", "проти годинникової стрілки", "против часовой стрелки"),
    "ws.angle": ("at {angle}° to x", "під кутом {angle}° до осі x", "под углом {angle}° к оси x"),
    "ws.accuracy": ("**Accuracy:** near a singular position: about {digits} significant digits left at this "
                    "angle (fewer than {min}); the last digits of the values below are not reliable",
                    "**Точність:** поблизу особливого положення: лишилося близько {digits} значущих цифр "
                    "(менше ніж {min}); останні цифри значень нижче ненадійні",
                    "**Точность:** вблизи особого положения: осталось около {digits} значащих цифр "
                    "(меньше чем {min}); последние цифры значений ниже ненадёжны"),
    "ws.head.symbol": ("Symbol", "Позначення", "Обозначение"),
    "ws.head.value": ("Value", "Значення", "Значение"),
    "ws.head.unit": ("Unit", "Одиниця", "Единица"),
    "ws.head.direction": ("Sense / direction", "Напрямок", "Направление"),
    "ws.head.note": ("How obtained", "Як отримано", "Как получено"),
    "degrees": ("deg", "град", "град"),
    # the teacher's pack (`pack`): the student's sheet, the answer key, the A3 sheet of plans
    "pack.sheet": ("Student's sheet", "Аркуш завдання студента", "Лист задания студента"),
    "pack.key": ("Answer key", "Ключ відповідей", "Ключ ответов"),
    "pack.a3": ("Plans of the mechanism", "Плани механізму", "Планы механизма"),
    "pack.task": ("Task {task}. {title}. Variant {code}", "Завдання {task}. {title}. Варіант {code}",
                  "Задание {task}. {title}. Вариант {code}"),
    "pack.statement": ("By the graphical-analytic method, at the design position φ1 of the crank determine: the "
                       "velocities and accelerations of the points and links (plans of positions, velocities and "
                       "accelerations), the inertia forces and moments, the reactions in the kinematic pairs (force "
                       "plans of the groups) and the balancing moment {M} (force plan of the initial link); check "
                       "{M} by Zhukovsky's lever and find the difference δ, which must not exceed 5 %.",
                       "Графоаналітичним методом у розрахунковому положенні кривошипа φ1 визначити: швидкості та "
                       "прискорення точок і ланок (плани положень, швидкостей і прискорень), сили та моменти сил "
                       "інерції, реакції в кінематичних парах (плани сил груп) і зрівноважувальний момент {M} (план "
                       "сил початкової ланки); перевірити {M} важелем Жуковського і знайти розбіжність δ, яка не "
                       "повинна перевищувати 5 %.",
                       "Графоаналитическим методом в расчётном положении кривошипа φ1 определить: скорости и "
                       "ускорения точек и звеньев (планы положений, скоростей и ускорений), силы и моменты сил "
                       "инерции, реакции в кинематических парах (планы сил групп) и уравновешивающий момент {M} (план "
                       "сил начального звена); проверить {M} рычагом Жуковского и найти расхождение δ, которое не "
                       "должно превышать 5 %."),
    "pack.assume": ("The crank turns clockwise at constant speed; φ1 is measured from top dead centre; friction "
                    "is neglected; g = 9.81 m/s².",
                    "Кривошип обертається за годинниковою стрілкою зі сталою швидкістю; φ1 відлічується від верхньої "
                    "мертвої точки; тертям знехтувати; g = 9,81 м/с².",
                    "Кривошип вращается по часовой стрелке с постоянной скоростью; φ1 отсчитывается от верхней "
                    "мёртвой точки; трением пренебречь; g = 9,81 м/с²."),
    "pack.data": ("Initial data (table {table}, the code's columns)", "Початкові дані (таблиця {table}, стовпці за "
                  "кодом)", "Исходные данные (таблица {table}, столбцы по коду)"),
    "pack.letter": ("Row", "Рядок", "Строка"),
    "pack.parameter": ("Parameter", "Параметр", "Параметр"),
    "pack.fill": ("Fill in from your plans", "Заповнити за своїми планами", "Заполнить по своим планам"),
    "pack.area": ("Drawing area: plans of positions, velocities, accelerations and forces, Zhukovsky's lever",
                  "Поле креслення: плани положень, швидкостей, прискорень і сил, важіль Жуковського",
                  "Поле чертежа: планы положений, скоростей, ускорений и сил, рычаг Жуковского"),
    "pack.student": ("Student", "Студент", "Студент"),
    "pack.group": ("Group", "Група", "Группа"),
    "pack.checked": ("Checked", "Перевірив", "Проверил"),
    "pack.band": ("Band of a careful drawing", "Межі ретельного креслення", "Границы тщательного чертежа"),
    "pack.band_note": ("Band: {lo}-{hi} % of {n} simulated careful drawings at these scales (every length laid off "
                       "or read wrong by up to ±{mm} mm, every direction by up to ±{deg}°); a drawn answer inside "
                       "the band is as good as a careful drawing gets.",
                       "Межі: {lo}-{hi} % з {n} змодельованих ретельних креслень у цих масштабах (кожна довжина "
                       "відкладена або виміряна з похибкою до ±{mm} мм, кожен напрямок до ±{deg}°); відповідь у "
                       "цих межах точна настільки, наскільки дозволяє ретельне креслення.",
                       "Границы: {lo}-{hi} % из {n} смоделированных тщательных чертежей в этих масштабах (каждая "
                       "длина отложена или измерена с погрешностью до ±{mm} мм, каждое направление до ±{deg}°); "
                       "ответ в этих границах точен настолько, насколько позволяет тщательный чертёж."),
    "pack.delta": ("δ = ({ML} - {M}) / {ML} · 100 %: the balancing moment by Zhukovsky's lever against that by "
                   "the force plans; the texts accept a drawing whose |δ| does not exceed 5 %. Exact: δ = {delta} %.",
                   "δ = ({ML} - {M}) / {ML} · 100 %: зрівноважувальний момент за важелем Жуковського проти "
                   "моменту за планами сил; допустима розбіжність |δ| не більше 5 %. Точно: δ = {delta} %.",
                   "δ = ({ML} - {M}) / {ML} · 100 %: уравновешивающий момент по рычагу Жуковского против "
                   "момента по планам сил; допустимое расхождение |δ| не более 5 %. Точно: δ = {delta} %."),
    "pack.band_outside": ("* The exact value lies outside the band: its segment is shorter than the drawing's own "
                          "error, so a careful drawing reads it too long; mark it by the band.",
                          "* Точне значення поза межами: його відрізок коротший за похибку самого креслення, тож "
                          "ретельне креслення дає його завеликим; оцінюйте за межами.",
                          "* Точное значение вне границ: его отрезок короче погрешности самого чертежа, поэтому "
                          "тщательный чертёж даёт его завышенным; оценивайте по границам."),
    "pack.delta_band": ("Careful drawings: δ = {lo} … {hi} %.", "Ретельні креслення: δ = {lo} … {hi} %.",
                        "Тщательные чертежи: δ = {lo} … {hi} %."),
    "pack.band_partial": ("The drawing-error study draws the force plans of groups {kinds} with the guide on "
                          "the frame only: here the reactions and {M} have no band.",
                          "Дослідження похибки креслення будує плани сил лише груп {kinds} з напрямною на "
                          "стояку: тут реакції та {M} без меж.",
                          "Исследование погрешности чертежа строит планы сил только групп {kinds} с "
                          "направляющей на стойке: здесь реакции и {M} без границ."),
    "pack.scales": ("Scales", "Масштаби", "Масштабы"),
    "pack.a3_true": ("Every plan true to scale: 1 mm drawn is 1 mm on this A3 sheet, at the scales above it",
                     "Кожен план у натуральну величину креслення: 1 мм плану = 1 мм на цьому аркуші А3, у масштабах над ним",
                     "Каждый план в натуральную величину чертежа: 1 мм плана = 1 мм на этом листе А3, в масштабах над ним"),
    "pack.no_band": ("— (from the data, not the plans)", "— (з даних, не з планів)", "— (из данных, не по планам)"),
    "pack.plan_scales": ("Scales of each plan", "Масштаби кожного плану", "Масштабы каждого плана"),
    # the A3 sheet's title block (GOST 2.104 form 1; DSTU GOST 2.104 in uk) and its notes
    "tb.rev": ("Rev.", "Зм.", "Изм."),
    "tb.sheet_no": ("Sheet", "Арк.", "Лист"),
    "tb.doc": ("Doc. No.", "№ докум.", "№ докум."),
    "tb.sign": ("Sign.", "Підпис", "Подп."),
    "tb.date": ("Date", "Дата", "Дата"),
    "tb.drawn": ("Drawn", "Розроб.", "Разраб."),
    "tb.checked": ("Checked", "Перев.", "Пров."),
    "tb.tech": ("T. contr.", "Т.контр.", "Т.контр."),
    "tb.norm": ("N. contr.", "Н.контр.", "Н.контр."),
    "tb.approved": ("Approved", "Затв.", "Утв."),
    "tb.letter": ("Lit.", "Літ.", "Лит."),
    "tb.mass": ("Mass", "Маса", "Масса"),
    "tb.scale": ("Scale", "Масштаб", "Масштаб"),
    "tb.sheet": ("Sheet", "Аркуш", "Лист"),
    "tb.sheets": ("Sheets", "Аркушів", "Листов"),
    "a3.departs": ("Outside the guide's recommended lengths: {items}",
                   "Поза рекомендованими посібником довжинами: {items}",
                   "Вне рекомендуемых пособием длин: {items}"),
    "a3.depart_one": ("{ref} {mm} mm ({lo}–{hi})", "{ref} {mm} мм ({lo}–{hi})", "{ref} {mm} мм ({lo}–{hi})"),
    "a3.packed": ("Packed to fit: in the texts' order the plans do not fit this sheet",
                  "Розміщено щільно: у порядку посібника плани не вміщуються на аркуші",
                  "Размещено плотно: в порядке пособия планы не помещаются на листе"),
    "pack.a3_page": ("Sheet {k} of {n}", "Аркуш {k} з {n}", "Лист {k} из {n}"),
    "pack.a3_more": ("The plans at their scales do not fit one A3 sheet: {n} sheets, none drawn smaller",
                     "Плани у своїх масштабах не вміщуються на одному аркуші А3: {n} аркуші, жоден не зменшено",
                     "Планы в своих масштабах не помещаются на одном листе А3: {n} листа, ни один не уменьшен"),
    "pack.a3_coarser": ("Scales coarser than the text's rule, so that all the plans fit this one sheet: {scales}",
                        "Масштаби дрібніші, ніж за правилом посібника, щоб усі плани вмістилися на цьому одному "
                        "аркуші: {scales}",
                        "Масштабы мельче, чем по правилу пособия, чтобы все планы поместились на этом одном листе: "
                        "{scales}"),
    "pack.instead": ("{scale} (rule: {rule})", "{scale} (за правилом {rule})", "{scale} (по правилу {rule})"),
    "pack.coarsened": ("Scales coarser than the text's rule, so that all the plans fit one A3 sheet (every length and "
                       "band in this key is at them): {scales}. The students' sheet gives them: drawn at the rule's, "
                       "their lengths would match none of this key's.",
                       "Масштаби дрібніші, ніж за правилом посібника, щоб усі плани вмістилися на одному аркуші А3 "
                       "(усі довжини й межі цього ключа — у них): {scales}. Аркуш завдання студента їх подає: у масштабах "
                       "за правилом їхні довжини не збіжуться з жодною довжиною цього ключа.",
                       "Масштабы мельче, чем по правилу пособия, чтобы все планы поместились на одном листе А3 "
                       "(все длины и границы этого ключа — в них): {scales}. Лист задания студента их приводит: в масштабах "
                       "по правилу их длины не совпадут ни с одной длиной этого ключа."),
    "pack.coarsened_within": ("{scale} instead of the rule's {rule}, {ref} drawn {mm} mm (still within the recommended "
                              "{lo}–{hi} mm)",
                              "{scale} замість {rule} за правилом, {ref} має {mm} мм (у межах рекомендованих {lo}–{hi} мм)",
                              "{scale} вместо {rule} по правилу, {ref} имеет {mm} мм (в пределах рекомендуемых {lo}–{hi} мм)"),
    "pack.coarsened_one": ("{scale} instead of the rule's {rule}, {ref} drawn {mm} mm, not the recommended {lo}–{hi} mm",
                           "{scale} замість {rule} за правилом, {ref} має {mm} мм, а не рекомендовані {lo}–{hi} мм",
                           "{scale} вместо {rule} по правилу, {ref} имеет {mm} мм, а не рекомендуемые {lo}–{hi} мм"),
    "pack.diagram_phi": ("Indicator diagram of {loads}: cylinder pressure p against the crank angle φ from TDC",
                         "Індикаторна діаграма для {loads}: тиск у циліндрі p за кутом повороту кривошипа φ від ВМТ",
                         "Индикаторная диаграмма для {loads}: давление в цилиндре p по углу поворота кривошипа φ от ВМТ"),
    "pack.diagram_travel": ("Pressure diagram of {loads}: gauge pressure p in the cylinder against the piston's travel s "
                            "from TDC (H the stroke), on the stroke from TDC and on the stroke to TDC",
                            "Діаграма тиску для {loads}: надлишковий тиск у циліндрі p за ходом поршня s від ВМТ "
                            "(H — хід поршня), на ході від ВМТ і на ході до ВМТ",
                            "Диаграмма давления для {loads}: избыточное давление в цилиндре p по ходу поршня s от ВМТ "
                            "(H — ход поршня), на ходе от ВМТ и на ходе к ВМТ"),
    "pack.diagram_note": ("The force on the piston is π d²/4 · p, towards the crank shaft; p is linear between the "
                          "table's points. Read at φ1 (the point marked): {marks}.",
                          "Сила на поршень дорівнює π d²/4 · p і спрямована до вала кривошипа; між точками таблиці p "
                          "змінюється лінійно. Прочитано при φ1 (позначена точка): {marks}.",
                          "Сила на поршень равна π d²/4 · p и направлена к валу кривошипа; между точками таблицы p "
                          "изменяется линейно. Прочитано при φ1 (отмеченная точка): {marks}."),
    "pack.diagram_scales": ("scales: μ_{x_name} = {mu_x} {x_unit}, μ_p = {mu_p} {p_unit}",
                            "масштаби: μ_{x_name} = {mu_x} {x_unit}, μ_p = {mu_p} {p_unit}",
                            "масштабы: μ_{x_name} = {mu_x} {x_unit}, μ_p = {mu_p} {p_unit}"),
    "pack.p_at": ("{loads}: p = {p} {unit} at {x_name} = {x}", "{loads}: p = {p} {unit} при {x_name} = {x}",
                  "{loads}: p = {p} {unit} при {x_name} = {x}"),
    "pack.p_down": ("p on the stroke from TDC, {unit}", "p на ході від ВМТ, {unit}", "p на ходе от ВМТ, {unit}"),
    "pack.p_up": ("p on the stroke to TDC, {unit}", "p на ході до ВМТ, {unit}", "p на ходе к ВМТ, {unit}"),
    "pack.model_data": ("Further data of the mechanism", "Інші дані механізму", "Прочие данные механизма"),
    "pack.g_crank": ("Weight of the crank (its centre of mass on the axis O)", "Вага кривошипа (центр мас на осі O)",
                     "Вес кривошипа (центр масс на оси O)"),
    "pack.i_link": ("Moment of inertia of link {k} about its centre of mass", "Момент інерції ланки {k} відносно її центра мас",
                    "Момент инерции звена {k} относительно его центра масс"),
    "pack.cylinder": ("Axis of the cylinder of piston {k}: through O, from O towards the piston (angle to the x axis)",
                      "Вісь циліндра поршня {k}: через O, від O до поршня (кут до осі x)",
                      "Ось цилиндра поршня {k}: через O, от O к поршню (угол к оси x)"),
    "pack.g_module": ("Module of the gear pair of the drive", "Модуль зубчастої пари приводу", "Модуль зубчатой пары привода"),
    "pack.g_z_pinion": ("Teeth of the pinion (motor side)", "Число зубців шестірні (з боку двигуна)",
                        "Число зубьев шестерни (со стороны двигателя)"),
    "pack.g_z_wheel": ("Teeth of the wheel on the crank shaft (the crank)", "Число зубців колеса на валу кривошипа (кривошип)",
                       "Число зубьев колеса на валу кривошипа (кривошип)"),
    "pack.sym_z_pinion": ("z_p", "z_ш", "z_ш"),
    "pack.sym_z_wheel": ("z_w", "z_к", "z_к"),
    "pack.g_alpha": ("Pressure angle of the mesh", "Кут зачеплення", "Угол зацепления"),
    "pack.g_correction": ("Centre distance modification coefficient (0: zero or equal modification)",
                          "Коефіцієнт сприйманого зміщення (0: нульове або рівнозміщене зачеплення)",
                          "Коэффициент воспринимаемого смещения (0: нулевое или равносмещённое зацепление)"),
    "pack.g_centres": ("Direction from the crank axis O to the pinion axis (angle to the x axis)",
                       "Напрям від осі кривошипа O до осі шестірні (кут до осі x)",
                       "Направление от оси кривошипа O к оси шестерни (угол к оси x)"),
    "pack.use_scales": ("Scales to draw the plans at (chosen so that all the plans fit one A3 sheet)",
                        "Масштаби, у яких креслити плани (обрані, щоб усі плани вмістилися на одному аркуші А3)",
                        "Масштабы, в которых чертить планы (выбраны, чтобы все планы поместились на одном листе А3)"),
    "pack.largest_force": ("the largest force", "найбільша сила", "наибольшая сила"),
    "pack.drawn": ("drawn", "відрізок", "отрезок"),
    "pack.segments": ("Segments a student measures, mm", "Відрізки, які вимірює студент, мм",
                      "Отрезки, которые измеряет студент, мм"),
    "pack.plan": ("Plan", "План", "План"),
    "pack.length": ("Length, mm", "Довжина, мм", "Длина, мм"),
    "pack.values": ("Values", "Значення", "Значения"),
    "pack.files": ("Sheet and key", "Завдання і ключ", "Задание и ключ"),
    # the rows of seed 002's tables 1.1-1.3, as the text words them
    "row.n1": ("Crank speed", "Частота обертання кривошипа", "Частота вращения кривошипа"),
    "row.l_OA": ("Crank length", "Довжина кривошипа", "Длина кривошипа"),
    "row.phi1": ("Design position of the mechanism", "Координата розрахункового положення механізму",
                 "Координата расчётного положения механизма"),
    "row.ratio": ("Ratio of the link lengths", "Співвідношення довжин ланок", "Соотношение длин звеньев"),
    "row.s_ratio": ("Position of the rod's centre of mass", "Положення центра мас шатуна",
                    "Положение центра масс шатуна"),
    "row.d": ("Cylinder diameter", "Діаметр циліндра", "Диаметр цилиндра"),
    "row.p_max": ("Maximum cylinder pressure", "Максимальний тиск у циліндрі", "Максимальное давление в цилиндре"),
    "row.G3": ("Piston weight", "Вага поршня", "Вес поршня"),
    "row.G2": ("Rod weight", "Вага шатуна", "Вес шатуна"),
    "row.I_S2": ("Rod moment of inertia about its centre of mass", "Момент інерції шатуна відносно центра мас",
                 "Момент инерции шатуна относительно центра масс"),
    "row.G_piston": ("Weight of the pistons", "Вага поршнів", "Вес поршней"),
    "row.G_rod": ("Weight of the rods", "Вага шатунів", "Вес шатунов"),
    # the interactive page (`page`)
    "page.phi": ("Crank angle φ", "Кут кривошипа φ", "Угол кривошипа φ"),
    "page.design": ("Design position", "Розрахункове положення", "Расчётное положение"),
    "page.next": ("Next step", "Наступний крок", "Следующий шаг"),
    "page.prev": ("Previous step", "Попередній крок", "Предыдущий шаг"),
    "page.values": ("Values at this angle", "Значення в цьому положенні", "Значения в этом положении"),
    "page.check": ("Check your drawing", "Перевірка креслення", "Проверка чертежа"),
    "page.check_note": ("Type the lengths you measured on your plans (mm) at φ = {phi}°: the deviation from the "
                   "exact length, and whether it lies in the band a careful drawing lands in (the 5-95 % "
                   "band of the drawing-error study; — where the study has none); the two balancing "
                   "moments with their sign (+ counter-clockwise), each against its band and sense, and "
                   "δ between your two by the texts' {tol} % rule.",
                   "Введіть довжини, виміряні на ваших планах (мм) при φ = {phi}°: відхилення від точної "
                   "довжини і чи лежить воно в смузі, куди потрапляє ретельне креслення (5-95 % "
                   "дослідження похибки креслення; — де його немає); два зрівноважувальні моменти зі "
                   "знаком (+ проти годинникової стрілки), кожен проти своєї смуги і напряму, і δ між "
                   "вашими двома за правилом {tol} % методички.",
                   "Введите длины, измеренные на ваших планах (мм) при φ = {phi}°: отклонение от точной "
                   "длины и лежит ли оно в полосе, куда попадает тщательный чертёж (5-95 % исследования "
                   "погрешности чертежа; — где его нет); два уравновешивающих момента со знаком (+ против "
                   "часовой стрелки), каждый против своей полосы и направления, и δ между вашими двумя по "
                   "правилу {tol} % методички."),
    "page.plan": ("Plan", "План", "План"),
    "page.segment": ("Segment", "Відрізок", "Отрезок"),
    "page.measured": ("Measured", "Виміряно", "Измерено"),
    "page.quantity": ("At your scale", "У вашому масштабі", "В вашем масштабе"),
    "page.your_scales": ("The scales you drew at (each length is judged at its own: the quantity it stands for "
                         "against the exact one; this page's scales to start with):",
                         "Масштаби, у яких ви креслили (кожну довжину оцінено у її масштабі: величину, яку "
                         "вона зображує, проти точної; спершу — масштаби цієї сторінки):",
                         "Масштабы, в которых вы чертили (каждая длина оценена в её масштабе: величина, которую "
                         "она изображает, против точной; сначала — масштабы этой страницы):"),
    "page.bad_scale": ("{mu}: type a number above 0", "{mu}: введіть число, більше за 0", "{mu}: введите число больше 0"),
    "page.exact": ("Exact", "Точно", "Точно"),
    "page.band": ("Band", "Смуга", "Полоса"),
    "page.verdict": ("Verdict", "Висновок", "Вывод"),
    "page.in_band": ("in the band", "у смузі", "в полосе"),
    "page.out_band": ("outside the band", "поза смугою", "вне полосы"),
    "page.negligible": ("under {tiny} mm at the plan's scale: negligible (not laid off, or drawn out of scale, marked *)",
                   "менше {tiny} мм у масштабі плану: нехтовно мала (не відкладена або показана не в масштабі, з *)",
                   "меньше {tiny} мм в масштабе плана: пренебрежимо мала (не отложена или показана не в масштабе, со *)"),
    "page.sense": ("the wrong sense (sign)", "не той напрям (знак)", "не то направление (знак)"),
    "page.both": ("type both moments", "введіть обидва моменти", "введите оба момента"),
    "page.rule_ok": ("within {tol} %", "в межах {tol} %", "в пределах {tol} %"),
    "page.rule_bad": ("beyond {tol} %", "понад {tol} %", "больше {tol} %"),
    "page.data": ("Data", "Вихідні дані", "Исходные данные"),
    "page.sheet": ("Your sheet (A3, true scale; print it)", "Ваш аркуш (A3, у натуральну величину; друкуйте)",
              "Ваш лист (A3, в натуральную величину; печатайте)"),
    "page.student": ("Student's page: no answers", "Сторінка студента: без відповідей", "Страница студента: без ответов"),
    "page.key": ("Key: every plan and value", "Ключ: усі плани і значення", "Ключ: все планы и значения"),
    "page.print": ("Print: each sheet at true scale, landscape, on the paper chosen (A4: the plan's part of the "
              "sheet; the 100 mm bar measures 100 mm).",
              "Друк: кожен аркуш у натуральну величину, альбомно, на вибраному папері (A4: частина аркуша з "
              "планом; відрізок 100 мм має 100 мм).",
              "Печать: каждый лист в натуральную величину, альбомно, на выбранной бумаге (A4: часть листа с "
              "планом; отрезок 100 мм имеет 100 мм)."),
    "page.paper": ("Paper", "Папір", "Бумага"),
    "page.a4_cut": ("the plan is larger than A4 and cut: print it on A3", "план більший за A4 і обрізаний: друкуйте на A3",
               "план больше A4 и обрезан: печатайте на A3"),
    "page.singular": ("a singular position: no plans at this angle", "особливе положення: планів немає",
                 "особое положение: планов нет"),
    "page.tau": ("{R} from ΣM_{P}(link {k}) = 0", "{R} з ΣM_{P}(ланка {k}) = 0", "{R} из ΣM_{P}(звено {k}) = 0"),
    "page.tau_S": ("{R} from ΣM_{P}(group {k}) = 0", "{R} з ΣM_{P}(група {k}) = 0", "{R} из ΣM_{P}(группа {k}) = 0"),
    "page.side": ("polygon: {sum} (side {n} of {m})", "многокутник: {sum} (сторона {n} з {m})",
             "многоугольник: {sum} (сторона {n} из {m})"),
    "page.vector": ("{plan}: {V}, known", "{plan}: {V}, відомий", "{plan}: {V}, известен"),
    "page.line": ("{plan}: through {P} the line of {V}, of known direction", "{plan}: через {P} лінія {V} відомого напрямку",
                  "{plan}: через {P} линия {V} известного направления"),
    "page.point": ("{plan}: {P} at the intersection of the lines", "{plan}: {P} на перетині ліній",
                   "{plan}: {P} на пересечении линий"),
    "page.inner": ("inner reaction {R}: ΣF(link {k}) = 0", "внутрішня реакція {R}: ΣF(ланка {k}) = 0",
              "внутренняя реакция {R}: ΣF(звено {k}) = 0"),
    "page.crank": ("initial link: {F}", "початкова ланка: {F}", "начальное звено: {F}"),
    "page.M_crank": ("{M} = Σ F·h about {O} (initial link)", "{M} = Σ F·h відносно {O} (початкова ланка)",
                "{M} = Σ F·h относительно {O} (начальное звено)"),
    "page.lever": ("Zhukovsky's lever: {F}", "важіль Жуковського: {F}", "рычаг Жуковского: {F}"),
    "page.M_lever": ("{M}' from the lever, δ against {tol} %", "{M}' з важеля, δ проти {tol} %",
                "{M}' с рычага, δ против {tol} %"),
    "page.scales": ("Scales (fixed for the whole cycle)", "Масштаби (сталі для всього циклу)",
               "Масштабы (постоянные для всего цикла)"),
    "page.loading": ("decoding…", "розпакування…", "распаковка…"),
    # the sheet of the law of motion (`motion_sheet`) and the summary of `kinetostat motion`
    "motion.title": ("Law of motion of the machine", "Закон руху машини", "Закон движения машины"),
    "motion.h_moments": ("Reduced moments", "Зведені моменти", "Приведённые моменты"),
    "motion.h_work": ("Work of the reduced moments", "Робота зведених моментів", "Работа приведённых моментов"),
    "motion.h_omega": ("Angular velocity of the crank", "Кутова швидкість кривошипа", "Угловая скорость кривошипа"),
    "motion.h_inertia": ("Reduced moment of inertia", "Зведений момент інерції", "Приведённый момент инерции"),
    "motion.h_energy": ("Change of kinetic energy", "Зміна кінетичної енергії", "Изменение кинетической энергии"),
    "motion.h_wittenbauer": ("Energy-mass diagram (Wittenbauer)", "Діаграма енергомас (Віттенбауера)",
                             "Диаграмма энергомасс (Виттенбауэра)"),
    "motion.sym_M_red": ("M_red", "M_зв", "M_пр"),
    "motion.sym_drive_engine": ("c", "сп", "потр"),          # an engine's consumer
    "motion.sym_drive_machine": ("d", "р", "дв"),            # a working machine's motor
    "motion.sym_A_red": ("A_red", "A_зв", "A_пр"),
    "motion.sym_J_red": ("J_red", "J_зв", "J_пр"),
    "motion.sym_J_fly": ("J_fly", "J_м", "J_м"),
    "motion.n_speed": ("ω_m = {omega} {unit}, δ = {delta}", "ω_m = {omega} {unit}, δ = {delta}",
                       "ω_m = {omega} {unit}, δ = {delta}"),
    "motion.n_target": (" (asked {delta})", " (задано {delta})", " (задано {delta})"),
    "motion.n_flywheel": ("flywheel {J} = {value} {unit} (exact); {M} = {M_value} {M_unit}",
                          "маховик {J} = {value} {unit} (точно); {M} = {M_value} {M_unit}",
                          "маховик {J} = {value} {unit} (точно); {M} = {M_value} {M_unit}"),
    "motion.n_ab": ("ab = {ab} {mm}: {J} = ab·μ_ΔT/(ω_m²·δ) = {value} {unit}",
                    "ab = {ab} {mm}: {J} = ab·μ_ΔT/(ω_m²·δ) = {value} {unit}",
                    "ab = {ab} {mm}: {J} = ab·μ_ΔT/(ω_m²·δ) = {value} {unit}"),
    "motion.n_approx": ("{method}: {J} = {value} {unit} ({diff} % from the exact)",
                        "{method}: {J} = {value} {unit} ({diff} % від точного)",
                        "{method}: {J} = {value} {unit} ({diff} % от точного)"),
    "motion.m_wittenbauer": ("Wittenbauer's diagram at ω_m(1 ± δ/2)", "діаграма Віттенбауера при ω_m(1 ± δ/2)",
                             "диаграмма Виттенбауэра при ω_m(1 ± δ/2)"),
    "motion.m_formula": ("the approximate formula", "наближена формула", "приближённая формула"),
    "motion.m_mertsalov": ("Mertsalov's method", "метод Мерцалова", "метод Мерцалова"),
}

#: The English phrases of the generated notes (positions, branches) and their translations,
#: longest first where one contains another.
PHRASES: tuple[tuple[str, str, str], ...] = (
    # what is not drawn (plans.zero), alternatives, special positions, forces off their link
    (" (dashed) replaces ", " (штрихова) замінює ", " (штриховая) заменяет "),
    (": one or the other acts, not both", ": діє одне або інше, не обидва", ": действует одно или другое, не оба"),
    (" and M_i", " і M_i", " и M_i"),
    (" (at this angle): not drawn", " (у цьому положенні): не показано", " (в этом положении): не показано"),
    (" translates): not drawn", " рухається поступально): не показано", " движется поступательно): не показано"),
    ("special position:", "особливе положення:", "особое положение:"),
    (", the plan collapses there", ", план тут вироджується", ", план здесь вырождается"),
    (" outside link ", " поза ланкою ", " вне звена "),
    (" m along the guide): the link's line drawn on to it, dashed", " м уздовж напрямної): лінію ланки продовжено до неї штрихом",
     " м вдоль направляющей): линия звена продолжена до неё штрихом"),
    (" acts ", " діє на відстані ", " действует на расстоянии "),
    (" m from ", " м від ", " м от "),
    ("(link ", "(ланка ", "(звено "),
    (": the mode the model draws at the design position (", ": складання, накреслене в розрахунковому положенні "
     "(усього складань: ", ": сборка, начерченная в расчётном положении (всего сборок: "),
    (" modes there)", ")", ")"),
    ("(crank and rod in line), then every 30 deg", "(кривошип і шатун на одній прямій), далі через 30°",
     "(кривошип и шатун на одной прямой), далее через 30°"),
    ("drawn with plain letters", "позначене літерами без індексу", "обозначено буквами без индекса"),
    ("design position phi =", "розрахункове положення φ =", "расчётное положение φ ="),
    ("position 0 at phi =", "положення 0 при φ =", "положение 0 при φ ="),
    ("(the other branch does not assemble here)", "(інше складання тут неможливе)", "(другая сборка здесь невозможна)"),
    ("(the other branch looks the same here)", "(інше складання тут має той самий вигляд)",
     "(другая сборка здесь выглядит так же)"),
    ("(the other branch", "(інше складання", "(другая сборка"),
    ("off the sheet at this scale)", "поза аркушем у цьому масштабі)", "вне листа в этом масштабе)"),
    (": the other branch", ": інше складання", ": другая сборка"),
    ("arm about the crank axis, on the crank's plan", "плече відносно осі кривошипа, на плані кривошипа",
     "плечо относительно оси кривошипа, на плане кривошипа"),
    ("of the crank (signed about +z)", "для кривошипа (знак відносно осі +z)", "для кривошипа (знак относительно оси +z)"),
    ("at the pitch point on the line of action", "у полюсі зачеплення на лінії зачеплення",
     "в полюсе зацепления на линии зацепления"),
    ("force plan of the crank", "план сил кривошипа", "план сил кривошипа"),
    ("the reactions with friction in the reactions", "реакції з тертям у реакціях", "реакции с трением в реакциях"),
    ("the reaction with friction in the reactions", "реакція з тертям у реакціях", "реакция с трением в реакциях"),
    (": the friction circle enlarged", ": коло тертя, збільшене в", ": круг трения, увеличенный в"),
    (" times, the line of", " разів, лінія", " раз, линия"),
    (" is tangent to it", " дотична до нього", " касается его"),
    (" tangent to it", " дотична до нього", " касается его"),
    ("friction circle", "коло тертя", "круг трения"),
    ("friction angle", "кут тертя", "угол трения"),
    (" deg (", "° (", "° ("),
    ("frictionless", "без тертя", "без трения"),
    ("leans from the normal to the guide", "відхилена від нормалі до напрямної", "отклонена от нормали к направляющей"),
    ("detail", "виносний елемент", "выносной элемент"),
    (", against the relative rotation", ", проти відносного обертання", ", против относительного вращения"),
    (", along the guide, against the sliding", ", уздовж напрямної, проти ковзання", ", вдоль направляющей, против скольжения"),
    ("friction in the reactions,", "тертя в реакціях,", "трение в реакциях,"),
    ("first approximation", "перше наближення", "первое приближение"),
    (" passes", " проходів", " проходов"),
    ("force plan of the group", "план сил групи", "план сил группы"),
    ("force plan of link", "план сил ланки", "план сил звена"),
    ("on the lever", "на важелі", "на рычаге"),
    ("along the guide of link", "уздовж напрямної ланки", "вдоль направляющей звена"),
    ("along the guide", "уздовж напрямної", "вдоль направляющей"),
    ("read from its diagram", "за діаграмою", "по диаграмме"),
    ("given", "задано", "задано"),
    (", against", ", протилежно", ", противоположно"),
    ("of link", "ланки", "звена"),
    (", arm", ", плече", ", плечо"),
    (" mm", " мм", " мм"),
    ("at point", "у точці", "в точке"),
    ("dashed to", "штрихом до", "штрихом до"),
    ("one assembly", "єдине складання", "единственная сборка"),
    ("branch", "складання", "сборка"),
    ("drawn", "накреслено", "начерчено"),
    (" deg", "°", "°"),
)

#: Units as each language writes them.
UNITS: dict[str, tuple[str, str, str]] = {
    "m/mm": ("m/mm", "м/мм", "м/мм"), "m/(s mm)": ("m/(s·mm)", "м/(с·мм)", "м/(с·мм)"),
    "m/(s^2 mm)": ("m/(s²·mm)", "м/(с²·мм)", "м/(с²·мм)"), "N/mm": ("N/mm", "Н/мм", "Н/мм"),
    "m/s": ("m/s", "м/с", "м/с"), "m/s^2": ("m/s²", "м/с²", "м/с²"), "m": ("m", "м", "м"), "mm": ("mm", "мм", "мм"),
    "N": ("N", "Н", "Н"), "N m": ("N·m", "Н·м", "Н·м"), "rad/s": ("rad/s", "рад/с", "рад/с"),
    "rad/s^2": ("rad/s²", "рад/с²", "рад/с²"), "kg": ("kg", "кг", "кг"), "kg m^2": ("kg·m²", "кг·м²", "кг·м²"),
    "rpm": ("rpm", "об/хв", "об/мин"), "Pa": ("Pa", "Па", "Па"), "MPa": ("MPa", "МПа", "МПа"), "%": ("%", "%", "%"),
    "deg": ("°", "°", "°"), "W": ("W", "Вт", "Вт"), "J": ("J", "Дж", "Дж"), "1": ("", "", ""), "": ("", "", ""),
}


def check_lang(lang: str) -> int:
    """Index of `lang` in LANGS (ValueError naming the choices otherwise)."""
    if lang not in LANGS:
        raise ValueError(f"lang: expected one of {', '.join(LANGS)}, got {lang!r}")
    return LANGS.index(lang)


#: Nouns counted by a message's {n}, by the form the catalogue writes: (one, few, many).
PLURALS = {"files": ("file", "files", "files"), "файлів": ("файл", "файли", "файлів"),
           "файлов": ("файл", "файла", "файлов")}


def plural(n: int, lang: str) -> int:
    """Which form (0 one, 1 few, 2 many) `lang` gives a noun counted n: en 1 file, 2 files; uk/ru
    1, 21 файл; 2-4, 22 файли/файла; 5-20, 11-14 файлів/файлов."""
    if check_lang(lang) == 0:
        return 0 if n == 1 else 2
    if n % 10 == 1 and n % 100 != 11:
        return 0
    return 1 if 2 <= n % 10 <= 4 and not 12 <= n % 100 <= 14 else 2


def text(key: str, lang: str, **fields) -> str:
    """Message `key` in `lang`, its {fields} filled; a noun after an integer {n} in its plural form."""
    s = MESSAGES[key][check_lang(lang)]
    n = fields.get("n")
    if isinstance(n, int) and not isinstance(n, bool):
        s = re.sub(r"\{n\} (\w+)", lambda m: "{n} " + PLURALS.get(m.group(1), (m.group(1),) * 3)[plural(n, lang)], s)
    return s.format(**fields) if fields else s


def unit(u: str, lang: str) -> str:
    """A unit as `lang` writes it (an unknown unit as given)."""
    return UNITS[u][check_lang(lang)] if u in UNITS else u


def num(x: float, lang: str, digits: int = 4, decimals: int | None = None) -> str:
    """x with `digits` significant digits (or `decimals` after the point), never in e-notation,
    trailing zeros dropped, the decimal comma in uk and ru; |x| < ZERO is 0; NaN is '—'."""
    x = float(x)
    if not math.isfinite(x):
        return "—"
    if abs(x) < ZERO:
        return "0"
    if decimals is not None:
        s = f"{x:.{decimals}f}"
    else:
        s = np.format_float_positional(x, precision=digits, unique=False, fractional=False, trim="-")
    s = s.rstrip(".")
    if s in ("-0", "0"):
        return "0"
    return s.replace(".", ",") if check_lang(lang) else s


def accuracy(digits: float, minimum: int, lang: str, markdown: bool = True) -> str:
    """The accuracy line ('ws.accuracy') near a singular position: about `digits` significant digits
    left (fewer than `minimum`), one decimal as `lang` writes it; Markdown's bold kept or dropped."""
    line = text("ws.accuracy", lang, digits=f"{digits:.1f}".replace(".", "." if lang == "en" else ","), min=minimum)
    return line if markdown else line.replace("**", "")


#: An Assur group as the generated notes name it: its class in Roman numerals, links, kind ("II(2,3) RRP",
#: "III(2,3,4,5) III3").
_GROUP = re.compile(r"\b(II|III)\((\d+(?:,\d+)*)\) ([RP]{3}|III\d)\b")
def group_name(label: str, kind: str, lang: str) -> str:
    """An Assur group in `lang`'s words: "II(2,3)", "RRP" -> "група 2-3 (2-го класу 2-го виду)"; in
    English its label and kind as the structure names them."""
    klass = {"II": 2, "III": 3}.get(label.partition("(")[0], 0)
    links = label.partition("(")[2].rstrip(")").replace(",", "-")
    if check_lang(lang) == 0:
        return f"{label} {kind}"
    if kind in GROUP_KINDS:
        return text("group.kind", lang, links=links, klass=klass, n=GROUP_KINDS[kind])
    return text("group.class", lang, links=links, klass=klass)


def phrase(note: str, lang: str) -> str:
    """A generated English note in `lang`, phrase by phrase (PHRASES), its groups in words
    (`group_name`); its numbers as `lang` writes them."""
    i = check_lang(lang)
    if not i:
        return note
    note = _GROUP.sub(lambda m: group_name(f"{m.group(1)}({m.group(2)})", m.group(3), lang), note)
    for p in PHRASES:
        note = note.replace(p[0], p[i])
    return re.sub(r"(?<=\d)\.(?=\d)", ",", note)


def words_en() -> set[str]:
    """The English words (3 letters or more) of the catalogue's English side, less its {fields}
    and `file names`: none may appear in uk or ru output."""
    texts = [m[0] for m in MESSAGES.values()] + [p[0] for p in PHRASES]
    return {w.lower() for t in texts for w in re.findall(r"[A-Za-z]{3,}", re.sub(r"\{[^}]*\}|`[^`]*`", "", t))}
